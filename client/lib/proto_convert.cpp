#include "client/lib/proto_convert.h"

#include <cmath>
#include <stdexcept>

namespace rrg::service {

namespace {
template <class Scalar>
v1::Pose pose_to_proto(const Eigen::Transform<Scalar, 3, Eigen::Isometry>& T) {
  const Eigen::Quaternion<Scalar> q(T.rotation());
  v1::Pose p;
  p.set_tx(double(T.translation().x()));
  p.set_ty(double(T.translation().y()));
  p.set_tz(double(T.translation().z()));
  p.set_qx(double(q.x()));
  p.set_qy(double(q.y()));
  p.set_qz(double(q.z()));
  p.set_qw(double(q.w()));
  return p;
}
}  // namespace

v1::Pose to_proto(const Eigen::Isometry3f& T) { return pose_to_proto(T); }
v1::Pose to_proto(const Eigen::Isometry3d& T) { return pose_to_proto(T); }

Eigen::Isometry3f from_proto(const v1::Pose& p, const std::string& field) {
  const double v[7] = {p.tx(), p.ty(), p.tz(), p.qx(), p.qy(), p.qz(), p.qw()};
  for (double x : v)
    if (!std::isfinite(x)) throw std::invalid_argument(field + ": non-finite value");
  Eigen::Quaterniond q(p.qw(), p.qx(), p.qy(), p.qz());
  if (!(q.norm() > 1e-6)) throw std::invalid_argument(field + ": quaternion is zero");
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.tx(), p.ty(), p.tz());
  return T.cast<float>();
}

v1::CameraIntrinsics to_proto(const Intrinsics& K) {
  v1::CameraIntrinsics k;
  k.set_fx(K.fx);
  k.set_fy(K.fy);
  k.set_cx(K.cx);
  k.set_cy(K.cy);
  k.set_width(uint32_t(std::max(0, K.width)));
  k.set_height(uint32_t(std::max(0, K.height)));
  return k;
}

Intrinsics from_proto(const v1::CameraIntrinsics& k) {
  Intrinsics K;
  K.fx = k.fx();
  K.fy = k.fy();
  K.cx = k.cx();
  K.cy = k.cy();
  // Sizes beyond int range become -1 so that validation names them instead of wrapping.
  K.width = k.width() > 1u << 30 ? -1 : int(k.width());
  K.height = k.height() > 1u << 30 ? -1 : int(k.height());
  return K;
}

v1::TrackingState to_proto(TrackingState s) {
  switch (s) {
    case TrackingState::Ok: return v1::TRACKING_OK;
    case TrackingState::Degraded: return v1::TRACKING_DEGRADED;
    case TrackingState::Lost: return v1::TRACKING_LOST;
  }
  return v1::TRACKING_STATE_UNSPECIFIED;
}

std::string to_string(v1::TrackingState s) {
  switch (s) {
    case v1::TRACKING_OK: return "ok";
    case v1::TRACKING_DEGRADED: return "degraded";
    case v1::TRACKING_LOST: return "lost";
    default: return "unspecified";
  }
}

}  // namespace rrg::service
