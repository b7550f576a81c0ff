// ObservedVariance: the temporal intensity variance the input frames show on each GT plane.
#include "core/planes/observed_variance.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace rrg {
namespace {

// A fronto-parallel wall at z = 2 m seen by a camera translated along x; world x < 0 is plane 1,
// x >= 0 plane 2. Plane 1 has intensity i1 in this view, plane 2 always 0.5. `occluded`: plane 1's
// pixels show an occluder at 1 m instead (same id, intensity 0.8).
struct WallView {
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  DepthImage depth;
  ColorImage color;
  LabelImage planes;
};

Intrinsics camera() { return {40.0f, 40.0f, 19.5f, 14.5f, 40, 30}; }

WallView wall_view(float tx, float i1, bool occluded = false) {
  const Intrinsics K = camera();
  WallView v{Eigen::Isometry3f::Identity(), DepthImage(K.width, K.height, 0.0f), ColorImage(K.width, K.height, Color::Zero()),
             LabelImage(K.width, K.height, 0)};
  v.T_wc.translation() = Eigen::Vector3f(tx, 0.0f, 0.0f);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const float wx = tx + K.unproject(float(x), float(y), 2.0f).x();
      const bool first = wx < 0.0f;
      v.planes(x, y) = first ? 1 : 2;
      v.depth(x, y) = first && occluded ? 1.0f : 2.0f;
      const float i = first ? (occluded ? 0.8f : i1) : 0.5f;
      v.color(x, y) = Color(i, i, i);
    }
  return v;
}

TEST(ObservedVariance, ChangingIntensityIsAboveTheThresholdAndConstantIsNot) {
  ObservedVariance ov(camera(), 0.05f, 2);
  for (const auto& [tx, i1] : {std::pair{0.0f, 0.2f}, {0.05f, 0.5f}, {0.10f, 0.8f}}) {
    const WallView v = wall_view(tx, i1);
    ov.add(v.T_wc, v.depth, v.color, v.planes);
  }
  EXPECT_EQ(ov.views(), 3u);
  const auto s = ov.stats({1, 2}, 0.01f);
  ASSERT_EQ(s.size(), 2u);
  // Plane 1: points seen in all three views have variance of {0.2, 0.5, 0.8} = 0.06; points near the
  // edge of the views are seen twice ({0.2, 0.5} or {0.5, 0.8}: 0.0225). All above 0.01.
  EXPECT_GT(s.at(1).points, 100);
  EXPECT_DOUBLE_EQ(s.at(1).fraction_above, 1.0);
  EXPECT_NEAR(s.at(1).median, 0.06, 1e-5);
  EXPECT_GT(s.at(1).mean, 0.0225 + 1e-4);  // the twice-seen edge points pull it under the median
  EXPECT_LT(s.at(1).mean, 0.06 - 1e-4);
  EXPECT_TRUE(s.at(1).verifiable(0.05));
  EXPECT_GT(s.at(2).points, 100);
  EXPECT_DOUBLE_EQ(s.at(2).fraction_above, 0.0);
  EXPECT_NEAR(s.at(2).median, 0.0, 1e-9);
  EXPECT_NEAR(s.at(2).mean, 0.0, 1e-9);
  EXPECT_FALSE(s.at(2).verifiable(0.05));
  // Only the planes asked for.
  EXPECT_EQ(ov.stats({2}, 0.01f).count(1), 0u);
}

// The paper's statistic averages the channels first, so a change of hue at constant intensity is no
// variance of x; PSNR counts it in every channel, and mean_rgb keeps it: views (0.2, 0.5, 0.8) and
// (0.8, 0.5, 0.2) give r and b a variance of 0.09 each and g none, 0.06 on average. Grey walls have
// mean_rgb = mean.
TEST(ObservedVariance, AHueChangeIsNoVarianceOfXButCountsInEveryChannel) {
  ObservedVariance ov(camera(), 0.05f, 2);
  for (const auto& [tx, c] : {std::pair{0.0f, Color(0.2f, 0.5f, 0.8f)}, {0.05f, Color(0.8f, 0.5f, 0.2f)}}) {
    WallView v = wall_view(tx, 0.5f);
    for (size_t i = 0; i < v.color.size(); ++i)
      if (v.planes[i] == 1) v.color[i] = c;
    ov.add(v.T_wc, v.depth, v.color, v.planes);
  }
  const auto s = ov.stats({1, 2}, 0.01f);
  EXPECT_NEAR(s.at(1).mean, 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.at(1).fraction_above, 0.0);
  EXPECT_NEAR(s.at(1).mean_rgb, 0.06, 1e-6);
  EXPECT_NEAR(s.at(2).mean_rgb, 0.0, 1e-9);
}

TEST(ObservedVariance, AnOccluderInFrontOfThePlaneIsNotAnObservationOfIt) {
  ObservedVariance ov(camera(), 0.05f, 2);
  for (const auto& [tx, i1, occ] : {std::tuple{0.0f, 0.2f, false}, {0.05f, 0.5f, false}, {0.10f, 0.0f, true}}) {
    const WallView v = wall_view(tx, i1, occ);
    ov.add(v.T_wc, v.depth, v.color, v.planes);
  }
  // The third view's plane-1 pixels are 1 m nearer: its 0.8 is no observation of the wall's points
  // (without the depth test the median would be 0.06), and its own points (at 1 m) are seen once.
  const auto s = ov.stats({1}, 0.01f);
  ASSERT_EQ(s.count(1), 1u);
  EXPECT_NEAR(s.at(1).median, 0.0225, 1e-5);
  EXPECT_NEAR(s.at(1).mean, 0.0225, 1e-5);  // every point is seen twice
  EXPECT_NEAR(s.at(1).mean_rgb, 0.0225, 1e-5);  // grey: the same in every channel
  EXPECT_DOUBLE_EQ(s.at(1).fraction_above, 1.0);
  // With δ_v above 0.0225 nothing is above it.
  EXPECT_DOUBLE_EQ(ov.stats({1}, 0.03f).at(1).fraction_above, 0.0);
}

TEST(ObservedVariance, RejectsBadArguments) {
  EXPECT_THROW(ObservedVariance(camera(), 0.05f, 0), std::invalid_argument);
  EXPECT_THROW(ObservedVariance(camera(), 0.0f, 2), std::invalid_argument);
  ObservedVariance ov(camera(), 0.05f);
  const WallView v = wall_view(0.0f, 0.5f);
  EXPECT_THROW(ov.add(v.T_wc, DepthImage(10, 10, 1.0f), v.color, v.planes), std::invalid_argument);
  EXPECT_THROW(ov.add(v.T_wc, v.depth, v.color, LabelImage(40, 29, 1)), std::invalid_argument);
  EXPECT_EQ(ov.views(), 0u);
  EXPECT_TRUE(ov.stats({1}, 0.01f).empty());
}

}  // namespace
}  // namespace rrg
