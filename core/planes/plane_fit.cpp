#include "core/planes/plane_fit.h"

#include <Eigen/Eigenvalues>

namespace rrg {

void PlaneMoments::merge(const PlaneMoments& o) {
  count_ += o.count_;
  for (int i = 0; i < 9; ++i) s_[i] += o.s_[i];
}

Eigen::Vector3d PlaneMoments::mean() const {
  if (count_ == 0) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d(s_[0], s_[1], s_[2]) / double(count_);
}

Eigen::Matrix3d PlaneMoments::covariance() const {
  if (count_ == 0) return Eigen::Matrix3d::Zero();
  const double n = double(count_);
  const Eigen::Vector3d mu = mean();
  Eigen::Matrix3d m;
  m << s_[3], s_[4], s_[5], s_[4], s_[6], s_[7], s_[5], s_[7], s_[8];
  return m / n - mu * mu.transpose();
}

PlaneFit fit_plane(const PlaneMoments& m, const Eigen::Vector3f& viewpoint) {
  PlaneFit fit;
  if (m.count() < 3) return fit;
  const Eigen::Vector3d c = m.mean();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m.covariance());
  const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(0.0);  // ascending
  if (!(lambda(1) > 1e-12)) return fit;                            // points on a line or a point
  Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
  if (n.dot(viewpoint.cast<double>() - c) < 0) n = -n;
  fit.plane = {n.cast<float>(), float(-n.dot(c))};
  fit.centroid = c.cast<float>();
  fit.mse = float(lambda(0));
  fit.curvature = float(lambda(0) / (lambda.sum() + 1e-30));
  fit.valid = true;
  return fit;
}

}  // namespace rrg
