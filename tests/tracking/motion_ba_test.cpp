// Motion-only bundle adjustment (core/tracking/motion_ba.h) on synthetic correspondences.
#include "core/tracking/motion_ba.h"
#include "core/tracking/se3.h"
#include "tests/tracking/box_scene.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace rrg {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kBf = 40.0;

struct Problem {
  Intrinsics K = test::test_intrinsics(640, 480);
  Eigen::Isometry3d T_true;
  std::vector<BaObservation> obs;
  std::vector<bool> is_outlier;
};

// n map points 1-5 m in front of the camera, projected with 0.5 px noise; a fraction replaced by
// random pixels (outliers). Half the observations carry the virtual-stereo coordinate.
Problem make_problem(int n, double outlier_fraction, uint32_t seed) {
  Problem p;
  p.T_true = test::look_at({0.3f, -0.2f, 1.1f}, {3.0f, 1.0f, 0.9f}).cast<double>();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (int i = 0; i < n; ++i) {
    const double u = U(rng) * (p.K.width - 1), v = U(rng) * (p.K.height - 1), z = 1.0 + 4.0 * U(rng);
    const Eigen::Vector3d p_c((u - p.K.cx) * z / p.K.fx, (v - p.K.cy) * z / p.K.fy, z);
    BaObservation o;
    o.X_w = p.T_true * p_c;
    const bool outlier = U(rng) < outlier_fraction;
    if (outlier) {
      o.uv = {U(rng) * (p.K.width - 1), U(rng) * (p.K.height - 1)};
    } else {
      o.uv = {u + noise(rng), v + noise(rng)};
    }
    if (i % 2 == 0) o.u_right = (outlier ? o.uv.x() : u) - kBf / z + (outlier ? 0.0 : noise(rng));
    if (o.u_right < 0) o.u_right = -1;
    p.obs.push_back(o);
    p.is_outlier.push_back(outlier);
  }
  return p;
}

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& T) {
  Vector6d xi;
  xi << 0.04, -0.03, 0.02, 2.0 * kDeg, -1.5 * kDeg, 1.0 * kDeg;
  return se3_exp(xi) * T;
}

// BaResult::information is the cost's curvature in the PosePrior's coordinates: with noise-free
// observations, moving the pose by e (T_wc ← exp(e) T_wc, a world-frame twist as the prior's)
// raises Σ Ω |z − π|² by eᵀ Λ e to second order. Checked along each axis and two mixed directions,
// with e small enough that every observation stays an inlier. (The BA's own coordinates, T_cw ←
// exp(ξ) T_cw, differ from these by the adjoint of a pose 3 m from the origin and would fail.)
TEST(MotionBa, InformationIsTheCostCurvatureInThePriorsCoordinates) {
  Problem p = make_problem(200, 0.0, 3);
  for (BaObservation& o : p.obs) {  // exact observations: the cost is 0 at the true pose
    const Eigen::Vector3d c = p.T_true.inverse() * o.X_w;
    o.uv = {p.K.fx * c.x() / c.z() + p.K.cx, p.K.fy * c.y() / c.z() + p.K.cy};
    if (o.u_right >= 0) o.u_right = o.uv.x() - kBf / c.z();
  }
  const BaResult r = optimize_pose(p.obs, p.K, kBf, p.T_true, BaParams{});
  ASSERT_EQ(r.inliers, int(p.obs.size()));
  std::vector<Vector6d> directions;
  for (int k = 0; k < 6; ++k) directions.push_back(Vector6d::Unit(k));
  directions.push_back((Vector6d() << 1, -2, 0.5, 3, 1, -1).finished().normalized());
  directions.push_back((Vector6d() << -0.3, 0.2, 1, -1, 2, 0.5).finished().normalized());
  for (const Vector6d& d : directions) {
    const Vector6d e = 2e-4 * d;  // 0.2 mm or 0.2 mrad
    const PoseScore s = score_pose(p.obs, p.K, kBf, se3_exp(e) * p.T_true, BaParams{});
    ASSERT_EQ(s.inliers, int(p.obs.size()));
    const double expected = e.dot(r.information * e);
    EXPECT_NEAR(s.cost, expected, 0.02 * expected) << "direction " << d.transpose();
  }
}

TEST(MotionBa, RecoversKnownPoseWith30PercentOutliers) {
  const Problem p = make_problem(300, 0.30, 7);
  const Eigen::Isometry3d T0 = perturbed(p.T_true);
  ASSERT_GT(translation_distance(T0, p.T_true), 0.04);
  const BaResult r = optimize_pose(p.obs, p.K, kBf, T0, BaParams{});
  EXPECT_LT(translation_distance(r.T_wc, p.T_true), 2e-3) << translation_distance(r.T_wc, p.T_true) * 1e3 << " mm";
  EXPECT_LT(rotation_distance(r.T_wc, p.T_true), 0.05 * kDeg) << rotation_distance(r.T_wc, p.T_true) / kDeg << " deg";
  // The χ² test separates the two populations.
  int kept_inliers = 0, kept_outliers = 0, inliers = 0, outliers = 0;
  for (size_t i = 0; i < p.obs.size(); ++i) {
    if (p.is_outlier[i]) {
      ++outliers;
      kept_outliers += r.inlier[i];
    } else {
      ++inliers;
      kept_inliers += r.inlier[i];
    }
  }
  ASSERT_GT(outliers, 60);
  EXPECT_GE(kept_inliers, int(0.9 * inliers));   // 95 % χ² test: ~5 % of true inliers rejected
  EXPECT_LE(kept_outliers, int(0.03 * outliers)); // a random pixel rarely lands within 2.5 px
  EXPECT_EQ(r.inliers, kept_inliers + kept_outliers);
  EXPECT_LT(r.rms_px, 1.0);
}

TEST(MotionBa, WithoutRobustRoundsOutliersWouldBias) {
  // The same data with a single non-robust round is visibly worse: the test above is not trivial.
  const Problem p = make_problem(300, 0.30, 7);
  BaParams plain;
  plain.rounds = 1;
  plain.chi2_mono = plain.chi2_stereo = 1e12;  // nothing rejected
  const BaResult r = optimize_pose(p.obs, p.K, kBf, perturbed(p.T_true), plain);
  EXPECT_GT(translation_distance(r.T_wc, p.T_true), 5e-3);
}

TEST(MotionBa, ExactDataConvergesToTruth) {
  const Problem p = make_problem(50, 0.0, 3);
  std::vector<BaObservation> exact = p.obs;
  for (BaObservation& o : exact) {  // re-project without noise
    const Eigen::Vector3d q = p.T_true.inverse() * o.X_w;
    o.uv = {p.K.fx * q.x() / q.z() + p.K.cx, p.K.fy * q.y() / q.z() + p.K.cy};
    if (o.u_right >= 0) o.u_right = o.uv.x() - kBf / q.z();
  }
  const BaResult r = optimize_pose(exact, p.K, kBf, perturbed(p.T_true), BaParams{});
  EXPECT_LT(translation_distance(r.T_wc, p.T_true), 1e-6);
  EXPECT_LT(rotation_distance(r.T_wc, p.T_true), 1e-6);
  EXPECT_EQ(r.inliers, 50);
}

TEST(MotionBa, PriorPullsTowardsItsPoseInProportionToItsInformation) {
  // Exact observations of T_true, a prior at T_prior 5 cm away. A weak prior leaves the truth, an
  // overwhelming one keeps the prior, and with both at T_true nothing moves.
  const Problem p = make_problem(100, 0.0, 5);
  Vector6d xi;
  xi << 0.05, 0.0, 0.0, 0.0, 0.0, 0.0;
  PosePrior prior;
  prior.T_wc = se3_exp(xi) * p.T_true;
  prior.information = Matrix6d::Identity() * 1e-6;
  const BaResult weak = optimize_pose(p.obs, p.K, kBf, p.T_true, BaParams{}, &prior);
  EXPECT_LT(translation_distance(weak.T_wc, p.T_true), 2e-3);
  prior.information = Matrix6d::Identity() * 1e12;
  const BaResult strong = optimize_pose(p.obs, p.K, kBf, p.T_true, BaParams{}, &prior);
  EXPECT_LT(translation_distance(strong.T_wc, prior.T_wc), 1e-4);
  EXPECT_GT(translation_distance(strong.T_wc, p.T_true), 0.045);
}

TEST(MotionBa, NoObservationsKeepsTheInitialPose) {
  const Intrinsics K = test::test_intrinsics(64, 48);
  const Eigen::Isometry3d T0 = test::look_at({1, 2, 3}, {0, 0, 0}).cast<double>();
  const BaResult r = optimize_pose({}, K, kBf, T0, BaParams{});
  EXPECT_EQ(r.inliers, 0);
  EXPECT_LT(translation_distance(r.T_wc, T0), 1e-6);  // float-made rotation: inverse() = transpose to ~1e-7
}

TEST(Se3, ExpOfSmallAndLargeTwists) {
  Vector6d xi;
  xi << 0.1, 0.2, 0.3, 0.0, 0.0, std::numbers::pi / 2;
  const Eigen::Isometry3d T = se3_exp(xi);
  EXPECT_NEAR((T.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);
  // t = J_l(φ) ρ for a rotation of 90° about z: J = I + (1 − cos θ)/θ² W + (θ − sin θ)/θ³ W²
  const double th = std::numbers::pi / 2, a = (1 - std::cos(th)) / th, b = (th - std::sin(th)) / th;
  // W ρ / θ = (−0.2, 0.1, 0), W² ρ / θ² = (−0.1, −0.2, 0)
  EXPECT_NEAR(T.translation().x(), 0.1 - a * 0.2 - b * 0.1, 1e-12);
  EXPECT_NEAR(T.translation().y(), 0.2 + a * 0.1 - b * 0.2, 1e-12);
  EXPECT_NEAR(T.translation().z(), 0.3, 1e-12);
  EXPECT_NEAR(rotation_distance(Eigen::Isometry3d::Identity(), T), th, 1e-12);
}

}  // namespace
}  // namespace rrg
