#include "core/tracking/icp.h"

#include "core/common/dispatch.h"
#include "core/tracking/icp_impl.h"
#include "core/tracking/se3.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace rrg {
namespace {

constexpr double kMinPairs = 30;  // fewer pairs than this: no step (a 6-DoF fit needs plenty)

Eigen::Matrix<double, 6, 6> full_jtj(const kernel::IcpSystem& s) {
  Eigen::Matrix<double, 6, 6> A;
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) A(r, c) = A(c, r) = s.jtj[k++];
  return A;
}

}  // namespace

kernel::IcpSystem reduce_icp_system(const VertexNormalMaps& source, const IcpModel& model,
                                    const Eigen::Isometry3f& T_wc, const IcpParams& params) {
  if (!model.vertices || !model.normals) throw std::invalid_argument("icp: the model has no vertex or normal map");
  const Device& dev = source.vertices.device();
  if (!(model.vertices->device() == dev) || !(model.normals->device() == dev))
    throw std::invalid_argument("icp: model maps are on " + model.vertices->device().to_string() +
                                " but the frame is on " + dev.to_string());
  if (model.vertices->width() != model.K.width || model.vertices->height() != model.K.height ||
      model.normals->width() != model.K.width || model.normals->height() != model.K.height)
    throw std::invalid_argument("icp: model maps do not match the model intrinsics " + model.K.to_string());
  const Eigen::Isometry3f T_ref_cw = model.T_wc.inverse();
  kernel::IcpArgs args{source.vertices.view(), source.normals.view(), model.vertices->view(),
                       model.normals->view(), model.K, T_ref_cw.linear(), T_ref_cw.translation(),
                       T_wc.linear(), T_wc.translation(), params.max_distance_m,
                       float(std::cos(params.max_normal_angle_deg * std::numbers::pi / 180.0)),
                       params.huber_delta_m, params.noise, 0.0f};  // noise weighting off unless asked
  args.agree_sigmas = params.agreement_sigmas;
  if (params.noise_weighting) {
    args.sigma_ref = params.noise.sigma(params.noise_reference_depth_m);
    if (params.model_sigma_m > 0.0f) {
      args.model_variance = params.model_sigma_m * params.model_sigma_m;
      args.sigma_ref = std::sqrt(args.sigma_ref * args.sigma_ref + args.model_variance);
    }
  }
  kernel::IcpSystem s;
  RRG_DISPATCH(dev, s = kernel::reduce_icp_cpu(args), s = kernel::reduce_icp_cuda(args));
  return s;
}

bool solve_icp_step(const kernel::IcpSystem& system, Eigen::Matrix<double, 6, 1>& xi) {
  if (system.inliers < kMinPairs) return false;
  const Eigen::Matrix<double, 6, 6> A = full_jtj(system);
  const Eigen::Matrix<double, 6, 1> b = -Eigen::Map<const Eigen::Matrix<double, 6, 1>>(system.jtr);
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(A);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
  const Eigen::Vector<double, 6> d = ldlt.vectorD();
  if (d.minCoeff() <= 1e-12 * std::max(1.0, d.maxCoeff())) return false;
  xi = ldlt.solve(b);
  return xi.allFinite();
}

IcpResult icp_align(const FramePyramid& frame, const IcpModel& model, const Eigen::Isometry3f& T_wc_init,
                    const IcpParams& params) {
  if (frame.levels.empty()) throw std::invalid_argument("icp_align: empty frame pyramid");
  IcpResult result;
  Eigen::Isometry3d T = T_wc_init.cast<double>();
  const int top = std::min<int>(int(frame.levels.size()), 3) - 1;
  // The last level-0 system and whether it is still valid at the final pose: when the last step
  // was rejected (no update) or below the convergence thresholds (< 0.1 mm), it serves as the
  // quality measure instead of one more full reduction.
  std::optional<kernel::IcpSystem> last;
  for (int l = top; l >= 0; --l) {
    const VertexNormalMaps& maps = frame.levels[size_t(l)].maps;
    for (int it = 0; it < params.iterations[l]; ++it) {
      const kernel::IcpSystem s = reduce_icp_system(maps, model, T.cast<float>(), params);
      if (l == 0) last = s;
      Eigen::Matrix<double, 6, 1> xi;
      if (!solve_icp_step(s, xi)) break;
      T = orthonormalized(se3_exp(xi) * T);
      ++result.iterations;
      const bool small = xi.head<3>().norm() < params.converge_translation_m &&
                         xi.tail<3>().norm() < params.converge_rotation_rad;
      if (l == 0) result.converged = small;
      if (small) break;
      if (l == 0) last.reset();  // T moved by more than the thresholds
    }
  }
  // Quality at the final pose, level 0.
  const kernel::IcpSystem s = last ? *last : reduce_icp_system(frame.levels[0].maps, model, T.cast<float>(), params);
  result.T_wc = T.cast<float>();
  result.inliers = int64_t(s.inliers);
  result.valid = int64_t(s.valid);
  result.inlier_ratio = s.valid > 0 ? float(s.inliers / s.valid) : 0.0f;
  result.agreeing = int64_t(s.agree);
  result.agreement = s.valid > 0 ? float(s.agree / s.valid) : 0.0f;
  result.rmse_m = s.inliers > 0 ? float(std::sqrt(s.r2 / s.inliers)) : 0.0f;
  result.rmse_ref_m = s.inliers > 0 ? float(std::sqrt(s.r2_ref / s.inliers)) : 0.0f;
  result.jtj = full_jtj(s);
  if (s.inliers >= kMinPairs) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(full_jtj(s), Eigen::EigenvaluesOnly);
    const auto ev = eig.eigenvalues();
    result.condition = ev(5) > 0 ? float(std::max(0.0, ev(0)) / ev(5)) : 0.0f;
  }
  const Eigen::Isometry3d T0 = T_wc_init.cast<double>();
  result.diverged = translation_distance(T, T0) > params.max_jump_m ||
                    rotation_distance(T, T0) > params.max_jump_deg * std::numbers::pi / 180.0;
  return result;
}

}  // namespace rrg
