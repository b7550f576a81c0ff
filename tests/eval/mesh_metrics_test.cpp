// Surface sampling, the kd-tree and NICE-SLAM accuracy / completion with known answers.
#include "core/eval/kd_tree.h"
#include "core/eval/mesh_metrics.h"
#include "core/eval/surface_sampling.h"
#include "tests/eval/eval_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace rrg::eval {
namespace {

using test::square;

TEST(KdTree, AgreesWithBruteForce) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> pts(5000);
  for (auto& p : pts) p = Eigen::Vector3f(u(rng), u(rng), 0.1f * u(rng));  // flat-ish, like a surface
  for (int k = 0; k < 50; ++k) pts.push_back(pts[k]);                       // duplicates
  const KdTree tree(pts);
  ASSERT_EQ(tree.size(), pts.size());
  for (int q = 0; q < 2000; ++q) {
    const float scale = q < 1000 ? 1.2f : 10.0f;  // half near the data, half far outside it
    const Eigen::Vector3f x(scale * u(rng), scale * u(rng), scale * u(rng));
    float best = std::numeric_limits<float>::infinity();
    for (const auto& p : pts) best = std::min(best, (p - x).squaredNorm());
    const KdTree::Neighbor n = tree.nearest(x);
    ASSERT_EQ(n.distance_sq, best) << "query " << q;
    ASSERT_EQ((pts[n.index] - x).squaredNorm(), best) << "index maps back to the input order";
  }
}

TEST(KdTree, RejectsEmptyAndNonFinite) {
  EXPECT_THROW(KdTree({}), std::invalid_argument);
  EXPECT_THROW(KdTree({Eigen::Vector3f(0, std::numeric_limits<float>::quiet_NaN(), 0)}), std::invalid_argument);
}

TEST(SurfaceSampling, UniformByAreaDeterministicAndOnTheSurface) {
  // Two disjoint squares of area 1 and 3 (z = 0 and z = 5): a quarter of the samples on the first,
  // within 5 σ = 5·√(0.25·0.75/N).
  TriangleMesh m = square(0, 0, 1, 1, 0);
  const TriangleMesh big = square(0, 0, 3, 1, 5);
  for (const auto& v : big.vertices) m.vertices.push_back(v);
  for (const auto& f : big.triangles) m.triangles.push_back(f + Eigen::Vector3i::Constant(4));
  EXPECT_NEAR(surface_area(m), 4.0, 1e-12);

  const size_t N = 40000;
  const auto a = sample_surface(m, N, 5), b = sample_surface(m, N, 5), c = sample_surface(m, N, 6);
  ASSERT_EQ(a.size(), N);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  size_t on_small = 0;
  double mean_x_big = 0.0;
  for (const auto& p : a) {
    const bool small = p.z() == 0.0f;
    ASSERT_TRUE(small || p.z() == 5.0f);
    ASSERT_GE(p.x(), 0.0f);
    ASSERT_LE(p.x(), small ? 1.0f : 3.0f);
    ASSERT_GE(p.y(), 0.0f);
    ASSERT_LE(p.y(), 1.0f);
    on_small += small;
    if (!small) mean_x_big += p.x();
  }
  EXPECT_NEAR(double(on_small) / N, 0.25, 5.0 * std::sqrt(0.25 * 0.75 / N));
  // Uniform in x over [0, 3]: mean 1.5, std of the mean √(9/12 / 30000) = 0.005.
  EXPECT_NEAR(mean_x_big / double(N - on_small), 1.5, 0.025);
}

TEST(SurfaceSampling, OrientedSamplesAreTheSamePointsWithTheirWindingNormals) {
  // The unit square (winding +z) and the same square at z = 1 wound the other way (normal −z).
  TriangleMesh m = square(0, 0, 1, 1, 0);
  m.vertices.insert(m.vertices.end(), {Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(1, 0, 1), Eigen::Vector3f(1, 1, 1)});
  m.triangles.push_back(Eigen::Vector3i(4, 6, 5));
  const OrientedSamples o = sample_surface_oriented(m, 5000, 3);
  EXPECT_EQ(o.points, sample_surface(m, 5000, 3));
  ASSERT_EQ(o.normals.size(), o.points.size());
  size_t up = 0, down = 0;
  for (size_t i = 0; i < o.points.size(); ++i) {
    const bool top = o.points[i].z() == 1.0f;
    const Eigen::Vector3f expected(0.0f, 0.0f, top ? -1.0f : 1.0f);
    ASSERT_TRUE(o.normals[i].isApprox(expected, 1e-6f)) << i;
    (top ? down : up) += 1;
  }
  EXPECT_GT(up, 0u);
  EXPECT_GT(down, 0u);
  TriangleMesh cloud;
  cloud.vertices = {Eigen::Vector3f(1, 2, 3)};
  EXPECT_TRUE(sample_surface_oriented(cloud, 10, 0).normals.empty());
}

TEST(SurfaceSampling, PointCloudsUseTheirVertices) {
  TriangleMesh cloud;
  cloud.vertices = {Eigen::Vector3f(1, 2, 3), Eigen::Vector3f(4, 5, 6)};
  EXPECT_EQ(sample_surface(cloud, 1000, 0), cloud.vertices);
  EXPECT_THROW(sample_surface(TriangleMesh{}, 10, 0), std::invalid_argument);
  TriangleMesh broken = square(0, 0, 1, 1, 0);
  broken.triangles.push_back(Eigen::Vector3i(0, 1, 7));
  EXPECT_THROW(sample_surface(broken, 10, 0), std::invalid_argument);
}

TEST(MeshMetrics, ParallelSquaresTwoCentimetresApart) {
  // The same 0.5 m square shifted 2 cm along its normal. Every distance is √(h² + r²) ≥ h, with r
  // the in-plane gap to the nearest sample; for density λ = N/A, E[r²] = 1/(πλ) = 4.0e-7 m², so
  // the mean is at most √(h² + 1/(πλ)) = 2.0010 cm (edges, where λ halves, add < 1e-4 cm).
  MeshEvalParams params;  // 200000 samples, τ = 3 cm
  const MeshMetrics m = evaluate_mesh(square(0, 0, 0.5, 0.5, 0.02), square(0, 0, 0.5, 0.5, 0.0), params);
  EXPECT_EQ(m.est_samples, 200000u);
  EXPECT_GE(m.accuracy_cm, 2.0 - 1e-4);
  EXPECT_NEAR(m.accuracy_cm, 2.0, 0.01);
  EXPECT_GE(m.completion_cm, 2.0 - 1e-4);
  EXPECT_NEAR(m.completion_cm, 2.0, 0.01);
  EXPECT_EQ(m.accuracy_ratio, 1.0);
  EXPECT_EQ(m.completion_ratio, 1.0);

  params.samples = 20000;  // 4 cm apart: nothing within τ = 3 cm
  const MeshMetrics far = evaluate_mesh(square(0, 0, 0.5, 0.5, 0.04), square(0, 0, 0.5, 0.5, 0.0), params);
  EXPECT_NEAR(far.accuracy_cm, 4.0, 0.05);
  EXPECT_EQ(far.accuracy_ratio, 0.0);
  EXPECT_EQ(far.completion_ratio, 0.0);
}

TEST(MeshMetrics, IdenticalMeshesGiveTheSamplingFloor) {
  // Independent samples (seeds s, s + 1) of one 1 m² square: the nearest of a Poisson set of density
  // λ is at mean distance 1/(2√λ) = 0.2236 cm for λ = 50000/m². Border points see half the density
  // (a 2 mm strip: < 1 % of the area), so ±10 % holds with a wide margin; it is not 0.
  MeshEvalParams params;
  params.samples = 50000;
  const TriangleMesh s = square(0, 0, 1, 1, 0);
  const MeshMetrics m = evaluate_mesh(s, s, params);
  const double floor_cm = 100.0 / (2.0 * std::sqrt(50000.0));
  EXPECT_NEAR(m.accuracy_cm, floor_cm, 0.1 * floor_cm);
  EXPECT_NEAR(m.completion_cm, floor_cm, 0.1 * floor_cm);
  EXPECT_EQ(m.accuracy_ratio, 1.0);
  EXPECT_EQ(m.completion_ratio, 1.0);
}

TEST(MeshMetrics, HalfReconstructedSquare) {
  // est covers y ∈ [0, 0.5] of the reference's unit square. Reference points with y > 0.5 are
  // y − 0.5 away: completion = ½·E[y − 0.5 | y > 0.5] = ½·0.25 m = 12.5 cm; completion ratio =
  // P(y < 0.5 + 0.03) = 0.53. The covered half adds ½ × its floor 1/(2√λ) = ½ × 0.158 cm (λ = 1e5/m²).
  // Std of the mean: 0.161 m / √50000 = 0.072 cm, of the ratio √(0.53·0.47/50000) = 0.0022: ±4 σ.
  // Accuracy stays at the sampling floor.
  MeshEvalParams params;
  params.samples = 50000;
  const MeshMetrics m = evaluate_mesh(square(0, 0, 1, 0.5, 0), square(0, 0, 1, 1, 0), params);
  EXPECT_NEAR(m.completion_cm, 12.5 + 0.5 * 0.158, 0.3);
  EXPECT_NEAR(m.completion_ratio, 0.53, 0.01);
  EXPECT_LT(m.accuracy_cm, 0.3);
  EXPECT_EQ(m.accuracy_ratio, 1.0);
}

TEST(MeshMetrics, RejectsEmptyMeshesAndBadThresholds) {
  const TriangleMesh s = square(0, 0, 1, 1, 0);
  try {
    evaluate_mesh(TriangleMesh{}, s);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("estimated mesh"), std::string::npos) << e.what();
  }
  EXPECT_THROW(evaluate_mesh(s, TriangleMesh{}), std::invalid_argument);
  MeshEvalParams bad;
  bad.threshold = 0.0;
  EXPECT_THROW(evaluate_mesh(s, s, bad), std::invalid_argument);
}

}  // namespace
}  // namespace rrg::eval
