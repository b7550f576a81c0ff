#include "core/eval/trajectory_metrics.h"

#include "core/eval/association.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rrg::eval {
namespace {

constexpr double kCm = 100.0;  // metres → centimetres

double rmse(std::span<const double> e) {
  double sum = 0.0;
  for (double v : e) sum += v * v;
  return std::sqrt(sum / double(e.size()));
}

double median(std::vector<double> v) {
  const size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  const double upper = v[n / 2];
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + n / 2));
}

}  // namespace

double rotation_angle(const Eigen::Matrix3d& R) {
  const double c = 0.5 * (R.trace() - 1.0);
  const double s = 0.5 * Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)).norm();
  return std::atan2(s, c);
}

AteResult absolute_trajectory_error(std::span<const Eigen::Vector3d> est,
                                    std::span<const Eigen::Vector3d> ref, bool with_scale) {
  AteResult out;
  out.matched = est.size();
  out.with_scale = with_scale;
  out.alignment = align_umeyama(est, ref, with_scale);  // checks sizes, n >= 3, finiteness

  std::vector<double> aligned(est.size()), raw(est.size());
  for (size_t i = 0; i < est.size(); ++i) {
    aligned[i] = kCm * (ref[i] - out.alignment.apply(est[i])).norm();
    raw[i] = kCm * (ref[i] - est[i]).norm();
  }
  out.rmse_cm = rmse(aligned);
  out.rmse_unaligned_cm = rmse(raw);
  double sum = 0.0;
  for (double e : aligned) sum += e;
  out.mean_cm = sum / double(aligned.size());
  out.max_cm = *std::max_element(aligned.begin(), aligned.end());
  out.median_cm = median(aligned);
  return out;
}

RpeResult relative_pose_error(std::span<const double> t, std::span<const Eigen::Isometry3d> est,
                              std::span<const Eigen::Isometry3d> ref, double delta_s, double scale) {
  if (t.size() != est.size() || t.size() != ref.size())
    throw std::invalid_argument("relative_pose_error: timestamps, estimated and reference poses differ in count");
  if (!std::isfinite(delta_s) || delta_s <= 0.0)
    throw std::invalid_argument("relative_pose_error: delta must be a positive number of seconds");
  if (!std::is_sorted(t.begin(), t.end()))
    throw std::invalid_argument("relative_pose_error: timestamps must be ascending");
  RpeResult out;
  out.delta_s = delta_s;
  const size_t n = t.size();
  if (n < 2) return out;

  std::vector<double> gaps(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) gaps[i] = t[i + 1] - t[i];
  const double tolerance = 0.5 * median(gaps);  // half a typical frame interval

  double sum_t2 = 0.0, sum_r2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    // j = argmin |t_j − (t_i + Δ)|
    const double target = t[i] + delta_s;
    size_t j = size_t(std::lower_bound(t.begin(), t.end(), target) - t.begin());
    if (j == n || (j > 0 && target - t[j - 1] < t[j] - target)) --j;
    if (j <= i || std::abs(t[j] - t[i] - delta_s) > tolerance) continue;

    Eigen::Isometry3d dP = est[i].inverse() * est[j];  // P_i⁻¹ P_j
    dP.translation() *= scale;
    const Eigen::Isometry3d dQ = ref[i].inverse() * ref[j];  // Q_i⁻¹ Q_j
    const Eigen::Isometry3d E = dQ.inverse() * dP;
    sum_t2 += E.translation().squaredNorm();
    const double angle = rotation_angle(E.linear());
    sum_r2 += angle * angle;
    ++out.pairs;
  }
  if (out.pairs > 0) {
    out.trans_rmse_cm = kCm * std::sqrt(sum_t2 / double(out.pairs));
    out.rot_rmse_deg = 180.0 / std::numbers::pi * std::sqrt(sum_r2 / double(out.pairs));
  }
  return out;
}

TrajectoryMetrics evaluate_trajectory(const io::Trajectory& est, const io::Trajectory& ref,
                                      const TrajectoryEvalParams& params) {
  TrajectoryMetrics out;
  out.est_poses = est.size();
  out.ref_poses = ref.size();
  const std::vector<PoseMatch> matches = associate_by_time(est, ref, params.max_time_difference);
  if (matches.size() < kMinAlignedPoses)
    throw std::runtime_error("only " + std::to_string(matches.size()) + " of " + std::to_string(est.size()) +
                             " estimated poses matched one of the " + std::to_string(ref.size()) +
                             " reference poses within " + std::to_string(params.max_time_difference) +
                             " s (need at least " + std::to_string(kMinAlignedPoses) + ")");

  std::vector<double> t;
  std::vector<Eigen::Vector3d> p_est, p_ref;
  std::vector<Eigen::Isometry3d> T_est, T_ref;
  for (const PoseMatch& m : matches) {
    t.push_back(est[m.est].timestamp);
    T_est.push_back(est[m.est].T_wc);
    T_ref.push_back(ref[m.ref].T_wc);
    p_est.push_back(est[m.est].T_wc.translation());
    p_ref.push_back(ref[m.ref].T_wc.translation());
  }
  out.ate = absolute_trajectory_error(p_est, p_ref, params.with_scale);
  out.rpe = relative_pose_error(t, T_est, T_ref, params.rpe_delta, out.ate.alignment.s);
  return out;
}

}  // namespace rrg::eval
