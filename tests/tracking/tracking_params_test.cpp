// The ablation switch, parameter checks, keyframe selection and match filtering.
#include "core/tracking/feature_matching.h"
#include "core/tracking/keyframes.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/tracking_params.h"

#include <gtest/gtest.h>

#include <numbers>

namespace rrg {
namespace {

TEST(TrackingMode, ParsesTheThreeAblationsAndRoundTrips) {
  EXPECT_EQ(parse_tracking_mode("icp"), TrackingMode::Icp);
  EXPECT_EQ(parse_tracking_mode("icp+orb"), TrackingMode::IcpOrb);
  EXPECT_EQ(parse_tracking_mode("icp+orb+mask"), TrackingMode::IcpOrbMask);
  for (TrackingMode m : {TrackingMode::Icp, TrackingMode::IcpOrb, TrackingMode::IcpOrbMask})
    EXPECT_EQ(parse_tracking_mode(to_string(m)), m);
}

TEST(TrackingMode, UnknownModeNamesTheTextAndTheChoices) {
  try {
    parse_tracking_mode("orb+icp");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'orb+icp'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("icp+orb+mask"), std::string::npos);
  }
  EXPECT_THROW(parse_tracking_mode("ICP"), std::invalid_argument);
  EXPECT_THROW(parse_tracking_mode(""), std::invalid_argument);
}

TEST(TrackingParams, DefaultsAreValidAndBadFieldsAreNamed) {
  EXPECT_NO_THROW(TrackingParams{}.validate());
  TrackingParams p;
  p.icp.min_agreement = 0.9f;  // above ok_agreement
  try {
    p.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("icp.min_agreement"), std::string::npos) << e.what();
  }
  TrackingParams q;
  q.preprocess.levels = 4;
  EXPECT_THROW(q.validate(), std::invalid_argument);
  TrackingParams n;
  n.icp.noise_reference_depth_m = 0.0f;
  EXPECT_THROW(n.validate(), std::invalid_argument);
  n.icp.noise_reference_depth_m = 1.0f;
  n.icp.noise.b = -1.0f;
  try {
    n.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("icp.noise"), std::string::npos);
  }
  n.icp.noise.b = 0.0019f;
  n.icp.model_sigma_m = -0.001f;
  try {
    n.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("icp.model_sigma_m"), std::string::npos);
  }
  n.icp.model_sigma_m = 0.0f;
  n.icp.noise.a = 0.0f;  // σ_n(z0) = 0 would divide by zero
  EXPECT_THROW(n.validate(), std::invalid_argument);
  n.icp.noise_weighting = false;  // the model is not used then
  EXPECT_NO_THROW(n.validate());
}

TEST(Keyframes, InsertedBeyondDeltaAngleOrDeltaMove) {
  KeyframeParams p;  // 10°, 0.1 m
  const Eigen::Isometry3f A = Eigen::Isometry3f::Identity();
  Eigen::Isometry3f B = A;
  B.translation() = Eigen::Vector3f(0.06f, 0.07f, 0.0f);  // 9.2 cm
  EXPECT_FALSE(needs_keyframe(A, B, p));
  B.translation() = Eigen::Vector3f(0.06f, 0.07f, 0.03f);  // 9.7 cm
  EXPECT_FALSE(needs_keyframe(A, B, p));
  B.translation() = Eigen::Vector3f(0.06f, 0.08f, 0.03f);  // 10.4 cm
  EXPECT_TRUE(needs_keyframe(A, B, p));
  const float deg = float(std::numbers::pi / 180.0);
  Eigen::Isometry3f R = A;
  R.rotate(Eigen::AngleAxisf(9.5f * deg, Eigen::Vector3f(1, 1, 0).normalized()));
  EXPECT_FALSE(needs_keyframe(A, R, p));
  R = A;
  R.rotate(Eigen::AngleAxisf(10.5f * deg, Eigen::Vector3f(1, 1, 0).normalized()));
  EXPECT_TRUE(needs_keyframe(A, R, p));
}

TEST(Keyframes, SetKeepsTheNewestAndListsNewestFirst) {
  KeyframeSet set(3);
  for (int i = 0; i < 5; ++i) {
    Keyframe kf;
    kf.id = i;
    set.add(std::move(kf));
  }
  ASSERT_EQ(set.size(), 3u);
  const auto r = set.recent(2);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0]->id, 4);
  EXPECT_EQ(r[1]->id, 3);
  EXPECT_EQ(set.recent(10).back()->id, 2);
}

TEST(FeatureMatching, RotationConsistencyKeepsTheThreeFullestBins) {
  // 30 bins of 12°: 5 matches near 0°, 4 near 100°, 3 near 200°, 2 near 300°, 1 at 50°.
  const std::vector<float> diff = {1, 2, 3, 4, 5, 100, 101, 102, 103, 200, 201, 202, 300, 301, 50};
  const std::vector<int> keep = rotation_consistent(diff, 30);
  EXPECT_EQ(keep, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
  // A bin under 10 % of the fullest is dropped even when among the three.
  std::vector<float> many(30, 10.0f);
  many.push_back(180.0f);
  EXPECT_EQ(rotation_consistent(many, 30).size(), 30u);
}

TEST(FeatureMatching, HammingDistanceCountsDifferingBits) {
  uint8_t a[32] = {}, b[32] = {};
  b[0] = 0xFF;
  b[31] = 0x01;
  b[17] = 0x30;
  EXPECT_EQ(hamming_distance(a, b), 8 + 1 + 2);
  EXPECT_EQ(hamming_distance(b, b), 0);
}

TEST(MaskSource, TrackingMaskThresholdsMeanReflectionColour) {
  ColorImage c(3, 1);
  c(0, 0) = Color(0.1f, 0.1f, 0.1f);   // mean 0.1: not > 0.1
  c(1, 0) = Color(0.3f, 0.0f, 0.01f);  // mean 0.103
  c(2, 0) = Color(0.0f, 0.0f, 0.0f);
  const MaskImage m = tracking_mask_from_reflection(c, 0.1f);
  EXPECT_EQ(m(0, 0), 0);
  EXPECT_EQ(m(1, 0), 1);
  EXPECT_EQ(m(2, 0), 0);
  float passed = -1.0f;  // the render callback gets the mask's threshold (its stop, mask_source.h)
  RenderedReflectionMasks source([&](size_t, const Eigen::Isometry3f&, float t) {
    passed = t;
    return ReflectionView{c, {}};
  }, 0.05f);
  const MaskImage rendered = source.mask(0, Eigen::Isometry3f::Identity());
  EXPECT_EQ(passed, 0.05f);
  EXPECT_EQ(rendered(0, 0), 1);  // mean 0.1 > 0.05
  EXPECT_EQ(rendered(2, 0), 0);
  // Pixels whose reflection is not modelled yet join the mask whatever C_r says there.
  MaskImage unmodelled(3, 1, 0);
  unmodelled(2, 0) = 1;
  RenderedReflectionMasks with_unknown([&](size_t, const Eigen::Isometry3f&, float) { return ReflectionView{c, unmodelled}; },
                                       0.1f);
  const MaskImage both = with_unknown.mask(0, Eigen::Isometry3f::Identity());
  EXPECT_EQ(both(0, 0), 0);
  EXPECT_EQ(both(1, 0), 1);
  EXPECT_EQ(both(2, 0), 1);
  RenderedReflectionMasks wrong_size([&](size_t, const Eigen::Isometry3f&, float) { return ReflectionView{c, MaskImage(2, 1, 1)}; },
                                     0.1f);
  EXPECT_THROW(wrong_size.mask(0, Eigen::Isometry3f::Identity()), std::invalid_argument);
  EXPECT_THROW(SynthReflectionMasks("/nonexistent/folder"), std::runtime_error);
}

}  // namespace
}  // namespace rrg
