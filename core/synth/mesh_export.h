#pragma once
// Ground-truth mesh of a synthetic scene: every primitive triangulated (planar faces as grids no
// coarser than max_edge, spheres and cylinders by angle), vertex colours = texture albedo at the
// vertex in display space (gamma 2.2, unlit), normals, and the plane id of each vertex's face.
#include "core/common/mesh.h"
#include "core/synth/scene.h"

namespace rrg::synth {

struct MeshExportParams {
  float max_edge = 0.025f;  // metres: grid spacing on faces (vertex colours sample the texture)
};

// Throws std::invalid_argument for max_edge <= 0 or an unfinalized scene.
TriangleMesh scene_mesh(const Scene& scene, const MeshExportParams& params = {});

}  // namespace rrg::synth
