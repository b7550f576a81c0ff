#pragma once
// Input preprocessing (paper §4.1.1): from a depth map D_k, the local vertex map V_k^l and normal
// map N_k^l in the camera frame. Runs on the device the depth lives on (CPU or CUDA).
// Invalid pixels (no depth, or a neighbour without depth) get V = N = (0, 0, 0).
#include "core/common/buffer.h"
#include "core/common/camera.h"

#include <Eigen/Core>

namespace rrg {

struct VertexNormalMaps {
  DeviceImage<Eigen::Vector3f> vertices;  // V_k^l, metres, camera frame
  DeviceImage<Eigen::Vector3f> normals;   // N_k^l, unit, facing the camera
};

// Throws std::invalid_argument when the depth size differs from the intrinsics' size.
VertexNormalMaps compute_vertex_normal_maps(const DeviceImage<float>& depth, const Intrinsics& K);
// The same into `out`, reusing its images when they already have the depth's size and device.
void compute_vertex_normal_maps_into(VertexNormalMaps& out, const DeviceImage<float>& depth, const Intrinsics& K);

}  // namespace rrg
