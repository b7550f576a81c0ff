// CAPE-class segmentation on analytic depth: a room corner (floor, back wall, side wall) and a
// step of two parallel planes, with known (n, b).
#include "core/planes/plane_segmentation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace rrg {
namespace {

Intrinsics test_camera() { return {256.0f, 256.0f, 159.5f, 119.5f, 320, 240}; }

// Ray-casts planes (camera frame): each pixel sees the nearest plane in front; gt holds its index + 1.
DepthImage render(const std::vector<Plane>& planes, const Intrinsics& K, LabelImage& gt, float noise = 0.0f) {
  DepthImage depth(K.width, K.height, 0.0f);
  gt = LabelImage(K.width, K.height, 0);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3f ray((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0f);  // z = 1
      float best = std::numeric_limits<float>::infinity();
      for (size_t i = 0; i < planes.size(); ++i) {
        const float denom = planes[i].n.dot(ray);
        if (std::abs(denom) < 1e-6f) continue;
        const float z = -planes[i].d / denom;
        if (z > 0.1f && z < best) best = z, gt(u, v) = uint16_t(i + 1);
      }
      if (std::isfinite(best)) {
        // deterministic pseudo-noise in [-noise, noise]
        const float r = float((u * 7919 + v * 104729) % 1000) / 999.0f * 2.0f - 1.0f;
        depth(u, v) = best + noise * r;
      }
    }
  return depth;
}

float angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0f, 1.0f)) * 180.0f / std::numbers::pi_v<float>;
}

// True when every pixel within `r` of (u, v) has the same GT label.
bool interior(const LabelImage& gt, int u, int v, int r) {
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du) {
      const int x = std::clamp(u + du, 0, gt.width() - 1), y = std::clamp(v + dv, 0, gt.height() - 1);
      if (gt(x, y) != gt(u, v)) return false;
    }
  return true;
}

// Checks that every GT plane is found within 1° / 1 cm and that interior pixels carry its label.
void expect_recovered(const std::vector<Plane>& truth, const PlaneSegmentation& seg, const LabelImage& gt) {
  ASSERT_EQ(seg.planes.size(), truth.size());
  std::vector<int> local_of(truth.size() + 1, 0);
  for (size_t g = 0; g < truth.size(); ++g) {
    // the detected plane with the most pixels of GT plane g
    std::vector<int64_t> votes(seg.planes.size() + 1, 0);
    for (size_t i = 0; i < gt.size(); ++i)
      if (gt[i] == g + 1) ++votes[seg.labels[i]];
    votes[0] = 0;
    const int l = int(std::max_element(votes.begin(), votes.end()) - votes.begin());
    ASSERT_GT(l, 0) << "GT plane " << g + 1 << " not detected";
    local_of[g + 1] = l;
    const LocalPlane& p = seg.planes[size_t(l - 1)];
    EXPECT_EQ(p.id, l);
    EXPECT_LT(angle_deg(p.plane.n, truth[g].n), 1.0f) << "plane " << g + 1;
    EXPECT_NEAR(p.plane.d, truth[g].d, 0.01f) << "plane " << g + 1;
  }
  int64_t checked = 0, wrong = 0;
  for (int v = 0; v < gt.height(); ++v)
    for (int u = 0; u < gt.width(); ++u) {
      if (!gt(u, v) || !interior(gt, u, v, 3)) continue;
      ++checked;
      wrong += seg.labels(u, v) != local_of[gt(u, v)] ? 1 : 0;
    }
  EXPECT_GT(checked, 40000);
  EXPECT_EQ(wrong, 0) << "of " << checked << " interior pixels";
}

TEST(PlaneSegmentation, RoomCornerPlanesRecoveredWithinOneDegreeAndOneCentimetre) {
  const Intrinsics K = test_camera();
  const std::vector<Plane> truth = {
      {Eigen::Vector3f(0, -1, 0), 1.0f},                          // floor y = 1 (camera 1 m above)
      {Eigen::Vector3f(0, 0, -1), 4.0f},                          // back wall z = 4
      {Eigen::Vector3f(0.8f, 0, -0.6f).normalized(), 1.5f}};      // slanted side wall
  LabelImage gt;
  const DepthImage depth = render(truth, K, gt);
  const PlaneSegmentation seg = segment_planes(depth, K);
  expect_recovered(truth, seg, gt);
  EXPECT_EQ(seg.cells_x, 40);  // 8-pixel cells (320 / 40)
  EXPECT_EQ(seg.cells_y, 30);
}

TEST(PlaneSegmentation, NoisyDepthStillWithinTolerance) {
  const Intrinsics K = test_camera();
  const std::vector<Plane> truth = {{Eigen::Vector3f(0, -1, 0), 1.2f}, {Eigen::Vector3f(0, 0, -1), 3.0f}};
  LabelImage gt;
  const DepthImage depth = render(truth, K, gt, 0.003f);  // ±3 mm
  expect_recovered(truth, segment_planes(depth, K), gt);
}

// Kinect v1 axial noise, σ(z) = 1.2 mm + 1.9 mm (z − 0.4)² (Nguyen et al. 2012, also the model of
// `rrg synth --noise`): 6 mm at 2 m, 16 mm at 3.2 m, Gaussian. Every plane must come out whole and
// nothing else may cover 1 % of the image (whole: over 90 % of its interior in one plane). Fails with the earlier planarity bound max(2 mm, 1 mm z²),
// 6-pixel cells and growth against the seed cell's plane (the far wall split into 10 pieces).
TEST(PlaneSegmentation, KinectNoiseKeepsEachPlaneWhole) {
  const Intrinsics K = test_camera();
  const std::vector<Plane> truth = {
      {Eigen::Vector3f(0, -1, 0), 1.0f},                      // floor 1 m below the camera
      {Eigen::Vector3f(0, 0, -1), 3.2f},                      // back wall at 3.2 m
      {Eigen::Vector3f(0.8f, 0, -0.6f).normalized(), 1.5f}};  // slanted side wall
  LabelImage gt;
  DepthImage depth = render(truth, K, gt);
  uint64_t state = 12345;
  const auto uniform = [&state] {  // deterministic LCG in (0, 1]
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (float((state >> 40) & 0xffffff) + 1.0f) / 16777216.0f;
  };
  for (size_t i = 0; i < depth.size(); ++i) {
    const float z = depth[i];
    if (z <= 0.0f) continue;
    const float g = std::sqrt(-2.0f * std::log(uniform())) * std::cos(2.0f * std::numbers::pi_v<float> * uniform());
    depth[i] = z + (0.0012f + 0.0019f * (z - 0.4f) * (z - 0.4f)) * g;
  }
  const PlaneSegmentation seg = segment_planes(depth, K);
  for (size_t g = 0; g < truth.size(); ++g) {  // the plane holding most of GT plane g, and its share
    std::vector<int64_t> votes(seg.planes.size() + 1, 0);
    int64_t interior_pixels = 0;
    for (int v = 0; v < gt.height(); ++v)
      for (int u = 0; u < gt.width(); ++u)
        if (gt(u, v) == g + 1 && interior(gt, u, v, 3)) ++interior_pixels, ++votes[seg.labels(u, v)];
    votes[0] = 0;
    const int l = int(std::max_element(votes.begin(), votes.end()) - votes.begin());
    ASSERT_GT(l, 0) << "GT plane " << g + 1 << " not detected";
    EXPECT_GT(double(votes[size_t(l)]), 0.9 * double(interior_pixels)) << "GT plane " << g + 1 << " split or lost";
    EXPECT_LT(angle_deg(seg.planes[size_t(l - 1)].plane.n, truth[g].n), 2.0f) << "plane " << g + 1;
  }
  size_t large = 0;
  for (const LocalPlane& p : seg.planes) large += p.pixels >= int64_t(gt.size() / 100) ? 1 : 0;
  EXPECT_EQ(large, truth.size());
}

TEST(PlaneSegmentation, ParallelStepIsTwoPlanes) {
  // Left half at z = 2, right half at z = 2.1: same normal, 10 cm apart -> two planes.
  const Intrinsics K = test_camera();
  DepthImage depth(K.width, K.height, 0.0f);
  LabelImage gt(K.width, K.height, 0);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      depth(u, v) = u < 160 ? 2.0f : 2.1f;
      gt(u, v) = u < 160 ? 1 : 2;
    }
  const std::vector<Plane> truth = {{Eigen::Vector3f(0, 0, -1), 2.0f}, {Eigen::Vector3f(0, 0, -1), 2.1f}};
  expect_recovered(truth, segment_planes(depth, K), gt);
}

TEST(PlaneSegmentation, EmptyDepthGivesNoPlanes) {
  const Intrinsics K = test_camera();
  const PlaneSegmentation seg = segment_planes(DepthImage(K.width, K.height, 0.0f), K);
  EXPECT_TRUE(seg.planes.empty());
  EXPECT_EQ(seg.planar_cells, 0);
}

TEST(PlaneSegmentation, SizeMismatchAndBadParamsThrow) {
  const Intrinsics K = test_camera();
  EXPECT_THROW(segment_planes(DepthImage(100, 100, 1.0f), K), std::invalid_argument);
  PlaneSegmentationParams p;
  p.grow_angle_deg = 95.0f;
  try {
    segment_planes(DepthImage(K.width, K.height, 1.0f), K, p);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("grow_angle_deg"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rrg
