// Closed-form alignment: exact recovery of known transforms, never a mirror, least-squares optimality.
#include "core/eval/alignment.h"
#include "tests/eval/eval_test_util.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <limits>
#include <random>
#include <vector>

namespace rrg::eval {
namespace {

std::vector<Eigen::Vector3d> random_points(std::mt19937_64& rng, size_t n) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<Eigen::Vector3d> p(n);
  for (auto& x : p) x = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

double cost(const Similarity3& S, const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  double c = 0.0;
  for (size_t i = 0; i < from.size(); ++i) c += (to[i] - S.apply(from[i])).squaredNorm();
  return c;
}

TEST(Alignment, RecoversRandomRigidTransformsExactly) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d T = test::random_rigid(rng);
    const auto from = random_points(rng, 3 + trial);  // down to the minimum of 3 points
    std::vector<Eigen::Vector3d> to;
    for (const auto& p : from) to.push_back(T * p);
    const Similarity3 S = align_umeyama(from, to);
    EXPECT_LT((S.R - T.linear()).norm(), 1e-10) << "trial " << trial;
    EXPECT_LT((S.t - T.translation()).norm(), 1e-10) << "trial " << trial;
    EXPECT_EQ(S.s, 1.0);
  }
}

TEST(Alignment, RecoversScaleOnlyWhenAsked) {
  std::mt19937_64 rng(8);
  const Eigen::Isometry3d T = test::random_rigid(rng);
  const double s = 2.5;
  const auto from = random_points(rng, 30);
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.push_back(s * (T.linear() * p) + T.translation());

  const Similarity3 sim = align_umeyama(from, to, /*with_scale=*/true);
  EXPECT_NEAR(sim.s, s, 1e-10);
  EXPECT_LT((sim.R - T.linear()).norm(), 1e-10);
  EXPECT_LT((sim.t - T.translation()).norm(), 1e-9);

  const Similarity3 rigid = align_umeyama(from, to);  // the rotation is still right, the fit is not exact
  EXPECT_EQ(rigid.s, 1.0);
  EXPECT_LT((rigid.R - T.linear()).norm(), 1e-10);
  EXPECT_GT(cost(rigid, from, to), 1.0);
}

TEST(Alignment, NeverReturnsAMirror) {
  // `to` is `from` mirrored in x: the best orthogonal map is the mirror; we must return a rotation.
  std::mt19937_64 rng(9);
  const auto from = random_points(rng, 40);
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.emplace_back(-p.x(), p.y(), p.z());
  const Similarity3 S = align_umeyama(from, to);
  EXPECT_NEAR(S.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((S.R * S.R.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Alignment, IsALeastSquaresMinimumUnderNoise) {
  std::mt19937_64 rng(10);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Eigen::Isometry3d T = test::random_rigid(rng);
  const auto from = random_points(rng, 100);
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.push_back(T * p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  const Similarity3 S = align_umeyama(from, to);
  const double best = cost(S, from, to);
  // Residuals of an optimal t sum to zero; any small rotation or translation nudge costs more.
  Eigen::Vector3d residual_sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) residual_sum += to[i] - S.apply(from[i]);
  EXPECT_LT(residual_sum.norm(), 1e-9);
  for (int axis = 0; axis < 3; ++axis)
    for (double eps : {-1e-3, 1e-3}) {
      Similarity3 nudged = S;
      nudged.R = Eigen::AngleAxisd(eps, Eigen::Vector3d::Unit(axis)).toRotationMatrix() * S.R;
      EXPECT_GT(cost(nudged, from, to), best);
      nudged = S;
      nudged.t[axis] += eps;
      EXPECT_GT(cost(nudged, from, to), best);
    }
}

TEST(Alignment, RejectsBadInput) {
  const std::vector<Eigen::Vector3d> two = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
  EXPECT_THROW(align_umeyama(two, two), std::invalid_argument);
  std::vector<Eigen::Vector3d> a(4, Eigen::Vector3d::Zero()), b(5, Eigen::Vector3d::Zero());
  EXPECT_THROW(align_umeyama(a, b), std::invalid_argument);
  b.resize(4);
  EXPECT_THROW(align_umeyama(a, b, /*with_scale=*/true), std::invalid_argument);  // all coincide
  a[1].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(align_umeyama(a, b), std::invalid_argument);
}

}  // namespace
}  // namespace rrg::eval
