#pragma once
// Marching-cubes case table, generated here (not copied): for each of the 256 inside/outside
// patterns of a cube's corners, the iso-surface polygons are traced on the cube's faces and fanned
// into triangles. On a face with two diagonal inside corners the inside corners are always cut off
// separately, a rule that depends only on the face, so neighbouring cubes agree and the mesh has
// no cracks. Triangles wind counter-clockwise seen from outside the surface (positive TSDF side).
//
// Corner c sits at offset (c & 1, (c >> 1) & 1, c >> 2). Edge e runs along axis a = e / 4 from
// the corner whose other two coordinates are the bits of e % 4 (in axis order), at 0 along a.
#include "core/common/hd.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace rrg::mc {

inline constexpr int kStride = 40;  // entries per case: up to 13 triangles' edges, then -1

// tri[case * kStride + k]: edge indices, three per triangle, -1 terminated.
const std::array<int8_t, 256 * kStride>& triangle_table();

// Lower corner offset and axis of edge e (see above).
RRG_HD inline Eigen::Vector3i edge_origin(int e) {
  const int a = e >> 2, b0 = e & 1, b1 = (e >> 1) & 1;
  return a == 0 ? Eigen::Vector3i(0, b0, b1) : (a == 1 ? Eigen::Vector3i(b0, 0, b1) : Eigen::Vector3i(b0, b1, 0));
}
RRG_HD inline int edge_axis(int e) { return e >> 2; }

}  // namespace rrg::mc
