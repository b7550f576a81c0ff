#pragma once
// Closed-form alignment of two corresponding point sets (Umeyama 1991 / Horn 1987): the similarity
// y ≈ s·R·x + t that minimises Σ‖y_i − (s·R·x_i + t)‖². Used to align an estimated trajectory to a
// reference before the ATE. Rigid (s = 1) by default; the scale is for monocular runs only.
#include <Eigen/Core>

#include <span>

namespace rrg::eval {

// x ↦ s·R·x + t. R is a proper rotation (det +1), s > 0.
struct Similarity3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1.0;

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return s * (R * x) + t; }
};

// Least-squares R, t (and s when with_scale) taking `from` onto `to`, SVD of the 3×3
// cross-covariance with the reflection correction diag(1, 1, det(U)·det(V)), so R is never a
// mirror. Throws std::invalid_argument when the sizes differ, there are fewer than 3 points, a
// coordinate is not finite, or (with_scale) the `from` points all coincide.
Similarity3 align_umeyama(std::span<const Eigen::Vector3d> from, std::span<const Eigen::Vector3d> to,
                          bool with_scale = false);

}  // namespace rrg::eval
