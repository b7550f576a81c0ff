#include "core/tracking/motion_ba.h"

#include "core/tracking/se3.h"

#include <cmath>

namespace rrg {
namespace {

struct Projection {
  bool ok = false;
  Eigen::Vector3d e = Eigen::Vector3d::Zero();  // z − π(p), third entry only for stereo
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();  // ∂π/∂ξ (of the prediction)
  int dims = 2;
  double chi2 = 0.0;
};

// π and its Jacobian for the left update T_cw ← exp(ξ) T_cw: ∂p/∂ξ = [I, −[p]×].
Projection project(const BaObservation& o, const Intrinsics& K, double bf, const Eigen::Isometry3d& T_cw) {
  Projection r;
  const Eigen::Vector3d p = T_cw * o.X_w;
  if (!(p.z() > 1e-6)) return r;
  const double iz = 1.0 / p.z(), fx = K.fx, fy = K.fy;
  const double u = fx * p.x() * iz + K.cx, v = fy * p.y() * iz + K.cy;
  Eigen::Matrix<double, 3, 3> dpi;
  dpi << fx * iz, 0, -fx * p.x() * iz * iz,  //
      0, fy * iz, -fy * p.y() * iz * iz,     //
      fx * iz, 0, -fx * p.x() * iz * iz + bf * iz * iz;
  Eigen::Matrix<double, 3, 6> dp;
  dp.leftCols<3>().setIdentity();
  dp.rightCols<3>() << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
  r.J = dpi * dp;
  r.e.x() = o.uv.x() - u;
  r.e.y() = o.uv.y() - v;
  r.dims = o.u_right >= 0.0 ? 3 : 2;
  if (r.dims == 3) r.e.z() = o.u_right - (u - bf * iz);
  r.chi2 = o.inv_sigma2 * r.e.head(r.dims).squaredNorm();
  r.ok = true;
  return r;
}

// Adjoint of T for twists [ρ; φ]: Ad = [[R, [t]× R], [0, R]].
Matrix6d adjoint(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  Eigen::Matrix3d tx;
  tx << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = tx * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

// Adds the prior's normal equations. With T_wc = T_cw⁻¹, the BA's update T_cw ← exp(ξ) T_cw is
// T_wc ← T_wc exp(−ξ) = exp(−Ad(T_wc) ξ) T_wc, so ∂e/∂ξ = −Ad(T_wc) to first order.
void add_prior(const PosePrior& prior, const Eigen::Isometry3d& T_cw, Matrix6d& H, Vector6d& g) {
  const Eigen::Isometry3d T_wc = T_cw.inverse();
  const Vector6d e = pose_difference_twist(T_wc, prior.T_wc);
  const Matrix6d A = -adjoint(T_wc);
  H += A.transpose() * prior.information * A;
  g -= A.transpose() * prior.information * e;
}

}  // namespace

BaResult optimize_pose(std::span<const BaObservation> observations, const Intrinsics& K, double bf,
                       const Eigen::Isometry3d& T_wc_init, const BaParams& params, const PosePrior* prior) {
  BaResult result;
  result.inlier.assign(observations.size(), 1);
  Eigen::Isometry3d T_cw = T_wc_init.inverse();
  const auto threshold = [&](int dims) { return dims == 3 ? params.chi2_stereo : params.chi2_mono; };
  for (int round = 0; round < params.rounds; ++round) {
    const bool robust = round < params.rounds - 1;
    for (int it = 0; it < params.iterations; ++it) {
      Matrix6d H = Matrix6d::Zero();
      Vector6d g = Vector6d::Zero();
      int used = 0;
      for (size_t i = 0; i < observations.size(); ++i) {
        if (!result.inlier[i]) continue;
        const Projection pr = project(observations[i], K, bf, T_cw);
        if (!pr.ok) continue;
        double w = observations[i].inv_sigma2;
        const double delta = std::sqrt(threshold(pr.dims)), norm = std::sqrt(pr.chi2);
        if (robust && norm > delta) w *= delta / norm;  // Huber: ρ'(s) for s = e^T Ω e
        const auto J = pr.J.topRows(pr.dims);
        H += w * J.transpose() * J;
        g += w * J.transpose() * pr.e.head(pr.dims);  // −Jᵀ r with r = π − z
        ++used;
      }
      if (used < 3) break;
      if (prior) add_prior(*prior, T_cw, H, g);
      const Eigen::LDLT<Matrix6d> ldlt(H);
      if (ldlt.info() != Eigen::Success) break;
      const Vector6d xi = ldlt.solve(g);
      if (!xi.allFinite()) break;
      T_cw = orthonormalized(se3_exp(xi) * T_cw);
      if (xi.norm() < 1e-10) break;
    }
    // Re-classify every observation (outliers may come back) at the pose of this round.
    for (size_t i = 0; i < observations.size(); ++i) {
      const Projection pr = project(observations[i], K, bf, T_cw);
      result.inlier[i] = pr.ok && pr.chi2 <= threshold(pr.dims) ? 1 : 0;
    }
  }
  double sum = 0.0;
  Matrix6d H = Matrix6d::Zero();  // in the BA's ξ (T_cw ← exp(ξ) T_cw)
  for (size_t i = 0; i < observations.size(); ++i) {
    if (!result.inlier[i]) continue;
    ++result.inliers;
    const Projection pr = project(observations[i], K, bf, T_cw);
    sum += pr.e.head<2>().squaredNorm();
    const auto J = pr.J.topRows(pr.dims);
    H += observations[i].inv_sigma2 * J.transpose() * J;
  }
  // The prior's e ≈ A ξ with A = −Ad(T_wc) (add_prior), so Λ_e = A⁻ᵀ H A⁻¹, A⁻¹ = −Ad(T_cw).
  const Matrix6d A_inv = adjoint(T_cw);
  result.information = A_inv.transpose() * H * A_inv;
  result.rms_px = result.inliers > 0 ? std::sqrt(sum / result.inliers) : 0.0;
  result.T_wc = T_cw.inverse();
  return result;
}

PoseScore score_pose(std::span<const BaObservation> observations, const Intrinsics& K, double bf,
                     const Eigen::Isometry3d& T_wc, const BaParams& params) {
  PoseScore score;
  const Eigen::Isometry3d T_cw = T_wc.inverse();
  for (const BaObservation& o : observations) {
    const Projection pr = project(o, K, bf, T_cw);
    const double th = pr.dims == 3 ? params.chi2_stereo : params.chi2_mono;
    if (pr.ok && pr.chi2 <= th) {
      ++score.inliers;
      score.cost += pr.chi2;
    } else {
      score.cost += th;
    }
  }
  return score;
}

}  // namespace rrg
