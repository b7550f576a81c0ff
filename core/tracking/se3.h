#pragma once
// Small SE(3) helpers for the pose solvers (host, double): the exponential map of a twist
// ξ = [ρ; φ] (translation first, as the ICP and BA Jacobians), and pose differences.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace rrg {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// exp(ξ^) with R = exp(φ^) (Rodrigues) and t = J_l(φ) ρ.
inline Eigen::Isometry3d se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  const double theta = phi.norm();
  Eigen::Matrix3d W;
  W << 0, -phi.z(), phi.y(), phi.z(), 0, -phi.x(), -phi.y(), phi.x(), 0;
  Eigen::Matrix3d R, J;
  if (theta < 1e-8) {
    R = Eigen::Matrix3d::Identity() + W;
    J = Eigen::Matrix3d::Identity() + 0.5 * W;
  } else {
    const double s = std::sin(theta), c = std::cos(theta), t2 = theta * theta;
    R = Eigen::Matrix3d::Identity() + (s / theta) * W + ((1 - c) / t2) * W * W;
    J = Eigen::Matrix3d::Identity() + ((1 - c) / t2) * W + ((theta - s) / (t2 * theta)) * W * W;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = J * rho;
  return T;
}

// Translation distance (metres) and rotation angle (radians) between two poses.
inline double translation_distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}
inline double rotation_distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Matrix3d R = a.linear().transpose() * b.linear();
  const double c = std::clamp((R.trace() - 1.0) * 0.5, -1.0, 1.0);
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), c);
}

// The pose difference as a world-frame twist, e = [ρ; φ] of D = T T_ref⁻¹ (ρ = D's translation,
// φ = D's angle-axis): the PosePrior's error (motion_ba.h), T ≈ exp(e) T_ref for small e.
inline Vector6d pose_difference_twist(const Eigen::Isometry3d& T, const Eigen::Isometry3d& T_ref) {
  const Eigen::Isometry3d D = T * T_ref.inverse();
  const Eigen::AngleAxisd aa(D.linear());
  Vector6d e;
  e.head<3>() = D.translation();
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

// Re-orthonormalises the rotation of a pose accumulated from many float updates.
inline Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return out;
}

}  // namespace rrg
