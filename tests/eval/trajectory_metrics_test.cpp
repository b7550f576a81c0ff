// Association, ATE and RPE on in-memory trajectories with known answers.
#include "core/eval/association.h"
#include "core/eval/trajectory_metrics.h"
#include "tests/eval/eval_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <cmath>
#include <numbers>
#include <random>

namespace rrg::eval {
namespace {

using test::smooth_trajectory;

TEST(Association, PairsJitteredStampsWithTheirOwnReference) {
  // ref at 30 Hz; est = ref stamps + jitter in [−8, 8] ms, every 10th missing, plus decoys half-way
  // between two frames (16.7 ms from both: inside max_dt, but always farther than the real pose).
  const io::Trajectory ref = smooth_trajectory(300);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.008, 0.008);
  io::Trajectory est;
  std::vector<size_t> truth;  // truth[e] = the reference index est[e] was made from, or SIZE_MAX
  for (size_t k = 0; k < ref.size(); ++k) {
    if (k % 10 == 0) continue;
    est.push_back({ref[k].timestamp + jitter(rng), ref[k].T_wc});
    truth.push_back(k);
    if (k % 10 != 9 && k + 1 < ref.size()) {
      est.push_back({ref[k].timestamp + 0.5 / 30.0, ref[k].T_wc});
      truth.push_back(SIZE_MAX);
    }
  }
  // Input order must not matter.
  std::vector<size_t> order(est.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  io::Trajectory shuffled;
  std::vector<size_t> shuffled_truth;
  for (size_t i : order) {
    shuffled.push_back(est[i]);
    shuffled_truth.push_back(truth[i]);
  }

  const auto matches = associate_by_time(shuffled, ref, 0.02);
  EXPECT_EQ(matches.size(), 270u);  // 300 minus every 10th
  for (const PoseMatch& m : matches) EXPECT_EQ(m.ref, shuffled_truth[m.est]) << "est stamp " << shuffled[m.est].timestamp;
  for (size_t i = 1; i < matches.size(); ++i)
    EXPECT_LT(shuffled[matches[i - 1].est].timestamp, shuffled[matches[i].est].timestamp);
}

TEST(Association, EachReferenceOnceClosestFirstWithinMaxDt) {
  io::Trajectory ref = {{1.0, {}}, {2.0, {}}, {3.0, {}}};
  io::Trajectory est = {{1.010, {}}, {0.995, {}}, {2.0195, {}}, {3.0205, {}}};
  const auto matches = associate_by_time(est, ref, 0.02);
  ASSERT_EQ(matches.size(), 2u);
  EXPECT_EQ(matches[0].est, 1u);  // 0.995 is closer to 1.0 than 1.010 is
  EXPECT_EQ(matches[0].ref, 0u);
  EXPECT_EQ(matches[1].est, 2u);  // 19.5 ms: in; 3.0205 is 20.5 ms away: out
  EXPECT_EQ(matches[1].ref, 1u);
  EXPECT_EQ(associate_by_time(est, ref, 0.021).size(), 3u);
  EXPECT_THROW(associate_by_time(est, ref, -1.0), std::invalid_argument);
}

TEST(Ate, TrajectoryAgainstItselfUnderARigidMotionIsZeroOnlyAfterAlignment) {
  const io::Trajectory ref = smooth_trajectory(200);
  std::mt19937_64 rng(11);
  const Eigen::Isometry3d G = test::random_rigid(rng);
  io::Trajectory est = ref;
  double raw_sq = 0.0;
  for (auto& p : est) {
    p.T_wc = G * p.T_wc;
    raw_sq += (p.T_wc.translation() - G.inverse() * p.T_wc.translation()).squaredNorm();
  }
  const TrajectoryMetrics m = evaluate_trajectory(est, ref);
  EXPECT_EQ(m.ate.matched, 200u);
  EXPECT_FALSE(m.ate.with_scale);
  EXPECT_LT(m.ate.rmse_cm, 1e-8);
  EXPECT_LT(m.ate.max_cm, 1e-8);
  EXPECT_NEAR(m.ate.rmse_unaligned_cm, 100.0 * std::sqrt(raw_sq / 200.0), 1e-9);
  EXPECT_GT(m.ate.rmse_unaligned_cm, 1.0);
  // RPE is relative: a common motion of the whole trajectory leaves it at zero.
  EXPECT_EQ(m.rpe.pairs, 200u - 30u);
  EXPECT_LT(m.rpe.trans_rmse_cm, 1e-8);
  EXPECT_LT(m.rpe.rot_rmse_deg, 1e-6);
}

TEST(Ate, IsotropicNoiseOfKnownRms) {
  // Per-axis σ = 1/√3 cm, so E‖e‖² = (1 cm)². After a 6-parameter fit on 3n residuals,
  // E[RMSE²] = (1 − 2/n) cm²; Var‖e‖² = 6(σ²)² = 2/3 cm⁴, so RMSE² has std √(2/(3n)) ≈ 0.015 for n = 3000
  // and RMSE ≈ 0.0075 (0.75 %). 4 % is > 5 σ. ‖e‖ is Maxwell distributed: mean 2σ√(2/π) = 0.9213 cm,
  // median 1.5382σ = 0.8881 cm.
  const size_t n = 3000;
  const io::Trajectory ref = smooth_trajectory(n);
  std::mt19937_64 rng(12);
  const double sigma = 0.01 / std::sqrt(3.0);
  std::normal_distribution<double> noise(0.0, sigma);
  const Eigen::Isometry3d G = test::random_rigid(rng);
  io::Trajectory est = ref;
  for (auto& p : est) {
    p.T_wc.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    p.T_wc = G * p.T_wc;
  }
  const TrajectoryMetrics m = evaluate_trajectory(est, ref);
  EXPECT_NEAR(m.ate.rmse_cm, 1.0, 0.04);
  EXPECT_NEAR(m.ate.mean_cm, 0.9213, 0.04);
  EXPECT_NEAR(m.ate.median_cm, 0.8881, 0.05);
  EXPECT_GT(m.ate.max_cm, m.ate.rmse_cm);
  EXPECT_GT(m.ate.rmse_unaligned_cm, 10.0);
}

TEST(Ate, SimilarityAlignmentOnlyWhenAsked) {
  const io::Trajectory ref = smooth_trajectory(100);
  io::Trajectory est = ref;
  for (auto& p : est) p.T_wc.translation() = 0.5 * p.T_wc.translation() + Eigen::Vector3d(1, 2, 3);
  TrajectoryEvalParams params;
  EXPECT_GT(evaluate_trajectory(est, ref, params).ate.rmse_cm, 1.0);
  params.with_scale = true;
  const TrajectoryMetrics m = evaluate_trajectory(est, ref, params);
  EXPECT_TRUE(m.ate.with_scale);
  EXPECT_NEAR(m.ate.alignment.s, 2.0, 1e-9);
  EXPECT_LT(m.ate.rmse_cm, 1e-8);
}

TEST(Ate, FewerThanThreeMatchesIsAnError) {
  const io::Trajectory ref = smooth_trajectory(10);
  io::Trajectory est = ref;
  for (size_t k = 2; k < est.size(); ++k) est[k].timestamp += 100.0;
  try {
    evaluate_trajectory(est, ref);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("only 2 of 10"), std::string::npos) << e.what();
  }
}

TEST(Rpe, ConstantTranslationalDriftPerSecond) {
  // P_i = (R_i, q_i + v t_i) ⇒ E_ij = (I, R_jᵀ v (t_j − t_i)), ‖trans E‖ = |v| Δ exactly, no rotation.
  const io::Trajectory ref = smooth_trajectory(300);
  const Eigen::Vector3d v(0.03, -0.04, 0.0);  // 5 cm/s
  io::Trajectory est = ref;
  for (auto& p : est) p.T_wc.translation() += v * (p.timestamp - ref.front().timestamp);
  const TrajectoryMetrics m = evaluate_trajectory(est, ref);
  EXPECT_EQ(m.rpe.pairs, 300u - 30u);  // the last 30 frames have no partner 1 s later
  EXPECT_NEAR(m.rpe.trans_rmse_cm, 5.0, 1e-6);
  EXPECT_LT(m.rpe.rot_rmse_deg, 1e-6);

  TrajectoryEvalParams half;
  half.rpe_delta = 0.5;
  const TrajectoryMetrics h = evaluate_trajectory(est, ref, half);
  EXPECT_EQ(h.rpe.pairs, 300u - 15u);
  EXPECT_NEAR(h.rpe.trans_rmse_cm, 2.5, 1e-6);  // cm per Δ = 0.5 s
}

TEST(Rpe, ConstantRotationalDriftPerSecond) {
  // P_i = Rz(ω t_i) Q_i ⇒ E_ij = Q_j⁻¹ Rz(ω Δ) Q_j, a conjugate of Rz(ωΔ): its angle is ωΔ exactly.
  const io::Trajectory ref = smooth_trajectory(300);
  const double omega = 2.0 * std::numbers::pi / 180.0;  // 2 deg/s
  io::Trajectory est = ref;
  for (auto& p : est)
    p.T_wc = Eigen::AngleAxisd(omega * (p.timestamp - ref.front().timestamp), Eigen::Vector3d::UnitZ()) * p.T_wc;
  const TrajectoryMetrics m = evaluate_trajectory(est, ref);
  EXPECT_NEAR(m.rpe.rot_rmse_deg, 2.0, 1e-6);
}

TEST(Rpe, ShortTrajectoryHasNoPairs) {
  const io::Trajectory ref = smooth_trajectory(20);  // 0.63 s long
  const TrajectoryMetrics m = evaluate_trajectory(ref, ref);
  EXPECT_EQ(m.rpe.pairs, 0u);
  EXPECT_TRUE(std::isnan(m.rpe.trans_rmse_cm));
}

TEST(RotationAngle, SmallAndLargeAngles) {
  for (double a : {1e-9, 1e-4, 0.5, 3.0})
    EXPECT_NEAR(rotation_angle(Eigen::AngleAxisd(a, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix()), a,
                1e-12);
}

}  // namespace
}  // namespace rrg::eval
