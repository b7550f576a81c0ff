#pragma once
// Per-pixel math of depth_maps.h, shared by both back ends: the only copy.
#include "core/common/camera.h"
#include "core/common/hd.h"
#include "core/common/span.h"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

namespace rrg::kernel {

// V_k^l(u) = D_k(u) K^-1 [u, 1]^T, or 0 where D_k(u) is invalid.
RRG_HD inline Eigen::Vector3f vertex_at(ImageView<const float> depth, const Intrinsics& K, int x, int y) {
  const float z = depth(x, y);
  if (!(z > 0.0f)) return Eigen::Vector3f::Zero();
  return K.unproject(float(x), float(y), z);
}

// N_k^l(u) from central differences of the vertices of `depth` (unprojected here, tap by tap):
// normalize((V(x+1)-V(x-1)) x (V(y+1)-V(y-1))), flipped to face the camera; 0 on the border or next
// to an invalid depth.
RRG_HD inline Eigen::Vector3f normal_at(ImageView<const float> depth, const Intrinsics& K, int x, int y) {
  if (x <= 0 || y <= 0 || x >= depth.width - 1 || y >= depth.height - 1) return Eigen::Vector3f::Zero();
  const Eigen::Vector3f c = vertex_at(depth, K, x, y), l = vertex_at(depth, K, x - 1, y),
                        r = vertex_at(depth, K, x + 1, y), u = vertex_at(depth, K, x, y - 1),
                        d = vertex_at(depth, K, x, y + 1);
  if (c.z() <= 0.0f || l.z() <= 0.0f || r.z() <= 0.0f || u.z() <= 0.0f || d.z() <= 0.0f)
    return Eigen::Vector3f::Zero();
  Eigen::Vector3f n = (r - l).cross(d - u);
  const float len = n.norm();
  if (!(len > 0.0f)) return Eigen::Vector3f::Zero();
  n /= len;
  return n.dot(c) > 0.0f ? Eigen::Vector3f(-n) : n;
}

}  // namespace rrg::kernel
