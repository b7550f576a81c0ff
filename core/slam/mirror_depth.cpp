#include "core/slam/mirror_depth.h"

#include <stdexcept>
#include <string>

namespace rrg {

MirroredCamera mirror_camera(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const Eigen::Vector4f& plane) {
  const float len = plane.head<3>().norm();
  if (!(len > 0)) throw std::invalid_argument("mirror_camera: the plane has a zero normal");
  const Eigen::Vector3f n = plane.head<3>() / len;
  const float d = plane.w() / len;
  const Eigen::Matrix3f H = Eigen::Matrix3f::Identity() - 2.0f * n * n.transpose();
  const Eigen::Matrix3f F = Eigen::Vector3f(-1.0f, 1.0f, 1.0f).asDiagonal();
  MirroredCamera m;
  m.K = K;
  m.K.cx = float(K.width - 1) - K.cx;
  m.T_wc.linear() = H * T_wc.linear() * F;
  m.T_wc.translation() = H * T_wc.translation() - 2.0f * d * n;
  return m;
}

Image<float> mirrored_depth(const std::function<RaycastResult(const Intrinsics&, const Eigen::Isometry3f&)>& raycast,
                            const Intrinsics& K, const Eigen::Isometry3f& T_wc, const Image<int32_t>& plane_ids,
                            std::span<const ReflectivePlane> planes) {
  if (plane_ids.width() != K.width || plane_ids.height() != K.height)
    throw std::invalid_argument("mirrored_depth: the plane-id map is " + std::to_string(plane_ids.width()) + "x" +
                                std::to_string(plane_ids.height()) + ", the camera " + K.to_string());
  Image<float> out(K.width, K.height, 0.0f);
  for (const ReflectivePlane& pl : planes) {
    bool seen = false;
    for (int32_t id : plane_ids.pixels()) seen = seen || id == pl.id;
    if (!seen) continue;
    const MirroredCamera m = mirror_camera(K, T_wc, pl.plane);
    const Image<float> D = raycast(m.K, m.T_wc).depth.to_host();
    for (int v = 0; v < K.height; ++v)
      for (int u = 0; u < K.width; ++u)
        if (plane_ids(u, v) == pl.id) out(u, v) = D(K.width - 1 - u, v);
  }
  return out;
}

}  // namespace rrg
