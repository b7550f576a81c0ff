#include "core/eval/alignment.h"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::eval {

Similarity3 align_umeyama(std::span<const Eigen::Vector3d> from, std::span<const Eigen::Vector3d> to,
                          bool with_scale) {
  if (from.size() != to.size())
    throw std::invalid_argument("align_umeyama: " + std::to_string(from.size()) + " source points for " +
                                std::to_string(to.size()) + " target points");
  const size_t n = from.size();
  if (n < 3) throw std::invalid_argument("align_umeyama: need at least 3 point pairs, got " + std::to_string(n));
  for (size_t i = 0; i < n; ++i)
    if (!from[i].allFinite() || !to[i].allFinite())
      throw std::invalid_argument("align_umeyama: point pair " + std::to_string(i) + " is not finite");

  // μ_x, μ_y
  Eigen::Vector3d mu_x = Eigen::Vector3d::Zero(), mu_y = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mu_x += from[i];
    mu_y += to[i];
  }
  mu_x /= double(n);
  mu_y /= double(n);

  // Σ_xy = 1/n Σ (y_i − μ_y)(x_i − μ_x)ᵀ, σ_x² = 1/n Σ ‖x_i − μ_x‖²
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double var_x = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d dx = from[i] - mu_x;
    sigma += (to[i] - mu_y) * dx.transpose();
    var_x += dx.squaredNorm();
  }
  sigma /= double(n);
  var_x /= double(n);

  // Σ = U D Vᵀ; S = diag(1, 1, ±1) so that det(R) = +1; R = U S Vᵀ.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d S = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2) = -1.0;

  Similarity3 out;
  out.R = svd.matrixU() * S.asDiagonal() * svd.matrixV().transpose();
  if (with_scale) {
    if (!(var_x > 0.0)) throw std::invalid_argument("align_umeyama: source points all coincide, scale undefined");
    out.s = svd.singularValues().dot(S) / var_x;  // s = tr(D S) / σ_x²
  }
  out.t = mu_y - out.s * (out.R * mu_x);
  return out;
}

}  // namespace rrg::eval
