#pragma once
// TriangleMesh <-> Draco (.drc) buffers, for GetMesh over the wire and `rrg mesh --out m.drc`.
// Positions, normals and colours are quantised (DracoOptions); plane ids travel losslessly as a
// 1-component int32 generic attribute. The face count is kept; the vertex order is not (Draco's
// edgebreaker reorders, and may split vertices on non-manifold edges). Details: docs/codecs.md.
#include "core/common/mesh.h"

#include <cstdint>
#include <span>
#include <vector>

namespace rrg::io {

struct DracoOptions {
  // Positions: each coordinate snapped to a grid of (2^bits - 1) steps over the mesh's largest
  // bounding-box extent, so the error per coordinate is at most extent / (2 * (2^bits - 1)):
  // 14 bits over a 10 m room = 0.31 mm, well below a 5 mm TSDF voxel.
  int position_bits = 14;  // 1..30
  int normal_bits = 10;    // 1..30 (octahedral)
  int color_bits = 8;      // colours are sent as uint8 RGB: the error is at most 0.5 / 255; must be 8
  int speed = 5;           // 0 (smallest) .. 10 (fastest); 10 = sequential coding (no reorder).
                           // A mesh with a face that repeats a vertex is always coded sequentially
                           // (edgebreaker would drop that face).
};

// Throws std::invalid_argument for an invalid mesh (TriangleMesh::validate), a mesh with no
// triangles, or options out of range; std::runtime_error when Draco fails.
std::vector<uint8_t> encode_draco(const TriangleMesh& mesh, const DracoOptions& options = {});
// Throws std::invalid_argument when the buffer is not a Draco triangle mesh (or is corrupt).
TriangleMesh decode_draco(std::span<const uint8_t> bytes);

}  // namespace rrg::io
