#pragma once
// PLY meshes. Writes binary little-endian with float x y z, optional nx ny nz, uchar red green
// blue, int plane_id, and a face list. Reads ascii and binary_little_endian meshes with any
// vertex properties (unknown ones skipped) and triangle (or polygon, fan-split) faces; point clouds
// (no faces) read as a mesh with no triangles.
#include "core/common/mesh.h"

#include <filesystem>

namespace rrg::io {

TriangleMesh read_ply_mesh(const std::filesystem::path& path);
void write_ply_mesh(const std::filesystem::path& path, const TriangleMesh& mesh);

}  // namespace rrg::io
