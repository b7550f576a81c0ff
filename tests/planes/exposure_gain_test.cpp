// The exposure gain of an identification frame against the map (core/planes/exposure_gain.h).
#include "core/planes/exposure_gain.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace rrg {
namespace {

constexpr int kW = 64, kH = 48;

// A map view with intensities spread over [0.1, 0.7] at 2 m, and a frame that sees it through
// `gain`. Of the frame's pixels, `view_dependent` of them show something else (a reflection: a
// random intensity); pixels of the map's reflection mask and pixels whose depth disagrees show
// something brighter still, which the estimator must not read.
struct Views {
  ColorImage frame, map;
  DepthImage frame_depth, map_depth;
  MaskImage map_reflection;
};

Views make_views(float gain, float view_dependent, uint32_t seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  Views v{ColorImage(kW, kH), ColorImage(kW, kH), DepthImage(kW, kH, 2.0f), DepthImage(kW, kH, 2.0f),
          MaskImage(kW, kH, 0)};
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Color c(0.1f + 0.6f * u01(rng), 0.1f + 0.6f * u01(rng), 0.1f + 0.6f * u01(rng));
      v.map(x, y) = c;
      v.frame(x, y) = gain * c;
      if (u01(rng) < view_dependent) v.frame(x, y) = Color::Constant(u01(rng));
      if (x < 8) {  // the map's reflective surface: the frame sees a bright reflection there
        v.map_reflection(x, y) = 1;
        v.frame(x, y) = Color::Constant(0.9f);
      }
      if (y < 6) {  // another surface in the frame (an occluder 30 cm in front)
        v.frame_depth(x, y) = 1.7f;
        v.frame(x, y) = Color::Constant(0.9f);
      }
      if (y == 10) v.frame_depth(x, y) = 0.0f;  // no depth
    }
  return v;
}

ExposureGain estimate(const Views& v, const ExposureGainParams& p = {}) {
  return estimate_exposure_gain(v.frame, v.frame_depth, v.map, v.map_depth, v.map_reflection, p);
}

TEST(ExposureGain, RecoversTheGainOfTheFrame) {
  for (const float gain : {0.7f, 1.0f, 1.3f}) {
    const ExposureGain g = estimate(make_views(gain, 0.0f));
    ASSERT_TRUE(g.estimated);
    EXPECT_NEAR(g.gain, gain, 1e-5f) << gain;
    EXPECT_GT(g.pixels, 500);
  }
}

TEST(ExposureGain, AThirdOfViewDependentPixelsMovesItLittle) {
  for (const float gain : {0.7f, 1.0f, 1.3f}) {
    const ExposureGain g = estimate(make_views(gain, 0.33f, 7));
    ASSERT_TRUE(g.estimated);
    EXPECT_NEAR(g.gain, gain, 0.03f * gain) << gain;
  }
}

TEST(ExposureGain, ReadsOnlyPixelsWhereFrameAndMapSeeTheSameMatteSurface) {
  // Frame and map agree exactly wherever they should be compared: the occluder, the reflective
  // strip and the pixels without depth, all brighter, must not lift the gain off 1.
  const ExposureGain g = estimate(make_views(1.0f, 0.0f));
  EXPECT_FLOAT_EQ(g.gain, 1.0f);
  EXPECT_EQ(g.pixels, (kW - 8) / 2 * ((kH - 6) / 2 - 1));  // stride 2; row 10 has no depth
}

TEST(ExposureGain, TooFewPixelsGiveNoEstimate) {
  Views v = make_views(1.3f, 0.0f);
  v.map_depth = DepthImage(kW, kH, 0.0f);  // the map sees nothing (the first frames)
  const ExposureGain g = estimate(v);
  EXPECT_FALSE(g.estimated);
  EXPECT_EQ(g.gain, 1.0f);
  EXPECT_EQ(g.pixels, 0);
}

TEST(ExposureGain, RejectsMismatchedImagesAndBadParameters) {
  const Views v = make_views(1.0f, 0.0f);
  EXPECT_THROW(estimate_exposure_gain(v.frame, v.frame_depth, ColorImage(kW - 1, kH), v.map_depth, v.map_reflection),
               std::invalid_argument);
  EXPECT_THROW(estimate_exposure_gain(v.frame, v.frame_depth, v.map, v.map_depth, MaskImage(kW, kH + 1)),
               std::invalid_argument);
  ExposureGainParams p;
  p.stride = 0;
  EXPECT_THROW(estimate(v, p), std::invalid_argument);
  p = {};
  p.min_intensity = 0.9f;
  p.max_intensity = 0.5f;
  EXPECT_THROW(estimate(v, p), std::invalid_argument);
}

}  // namespace
}  // namespace rrg
