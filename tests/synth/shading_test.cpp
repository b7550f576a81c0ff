// Known-answer tests of the small shading functions and the hashes behind every random choice.
#include "core/synth/hash.h"
#include "core/synth/shading.h"
#include "core/synth/texture.h"

#include <gtest/gtest.h>

#include <set>

namespace rrg::synth {

TEST(Fresnel, SchlickEndpointsAndMidpoint) {
  for (float f0 : {0.0f, 0.04f, 0.25f, 0.9f, 1.0f}) {
    EXPECT_FLOAT_EQ(fresnel_schlick(f0, 1.0f), f0) << "normal incidence gives F0";
    EXPECT_FLOAT_EQ(fresnel_schlick(f0, 0.0f), 1.0f) << "grazing incidence gives 1";
  }
  // F0 = 0.04, cos = 0.5: 0.04 + 0.96 * 0.5^5 = 0.07.
  EXPECT_NEAR(fresnel_schlick(0.04f, 0.5f), 0.07f, 1e-7f);
  // Out-of-range cosines clamp.
  EXPECT_FLOAT_EQ(fresnel_schlick(0.2f, 1.5f), 0.2f);
  EXPECT_FLOAT_EQ(fresnel_schlick(0.2f, -0.3f), 1.0f);
  // Monotonic: more grazing, more reflection.
  float prev = 0.0f;
  for (float c = 1.0f; c >= 0.0f; c -= 0.05f) {
    const float f = fresnel_schlick(0.1f, c);
    EXPECT_GE(f, prev);
    prev = f;
  }
}

TEST(ToneMap, ZeroMonotonicAndBounded) {
  EXPECT_FLOAT_EQ(tone_map(0.0f, 1.6f), 0.0f);
  EXPECT_FLOAT_EQ(tone_map(-1.0f, 1.6f), 0.0f);
  // 1 - exp(-1) = 0.632121; ^(1/2.2) = exp(-0.458675 / 2.2) = 0.811810.
  EXPECT_NEAR(tone_map(1.0f, 1.0f), 0.811810f, 1e-5f);
  float prev = -1.0f;
  for (float x = 0.0f; x < 5.0f; x += 0.1f) {
    const float y = tone_map(x, 1.6f);
    EXPECT_GT(y, prev);
    EXPECT_LE(y, 1.0f);
    prev = y;
  }
}

TEST(WrappedLambert, KnownValues) {
  EXPECT_FLOAT_EQ(wrapped_lambert(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(wrapped_lambert(0.0f, 0.25f), 0.2f);
  EXPECT_FLOAT_EQ(wrapped_lambert(-0.25f, 0.25f), 0.0f);
  EXPECT_FLOAT_EQ(wrapped_lambert(-1.0f), 0.0f);
}

TEST(Hash, DeterministicWellSpreadAndInRange) {
  EXPECT_EQ(hash_u32(12345u), hash_u32(12345u));
  EXPECT_NE(hash_u32(1u), hash_u32(2u));
  EXPECT_NE(hash3(1, 2, 3), hash3(3, 2, 1)) << "order matters";
  std::set<uint32_t> seen;
  double mean = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const uint32_t h = hash3(uint32_t(i), 7u, 11u);
    seen.insert(h);
    const float u = unit_float(h);
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    mean += u;
  }
  EXPECT_GT(seen.size(), size_t(n - 5)) << "almost no collisions";
  EXPECT_NEAR(mean / n, 0.5, 0.01);
  // Gaussian draws: mean 0, variance 1.
  double m = 0.0, v = 0.0;
  for (int i = 0; i < n; ++i) {
    const double g = gaussian_from_hash(uint32_t(i) * 2654435761u);
    m += g;
    v += g * g;
  }
  EXPECT_NEAR(m / n, 0.0, 0.03);
  EXPECT_NEAR(v / n, 1.0, 0.05);
}

TEST(Texture, EveryKindStaysInRangeAndHasDetail) {
  const Texture base{TextureKind::Solid, srgb(200, 150, 100), srgb(60, 90, 120), srgb(20, 20, 20), 0.3f, 0.004f};
  for (int k = 0; k <= int(TextureKind::Metal); ++k) {
    Texture t = base;
    t.kind = TextureKind(k);
    double lo = 1e9, hi = -1e9;
    for (int i = 0; i < 400; ++i) {
      const Eigen::Vector2f uv(0.0137f * float(i % 20) + 0.05f, 0.0191f * float(i / 20) + 0.05f);
      const Color c = eval_texture(t, uv, {1.0f, 1.0f}, 42u);
      ASSERT_TRUE((c.array() >= 0.0f).all() && (c.array() <= 1.0f).all()) << "kind " << k;
      EXPECT_EQ(c, eval_texture(t, uv, {1.0f, 1.0f}, 42u)) << "pure function";
      lo = std::min<double>(lo, c.sum());
      hi = std::max<double>(hi, c.sum());
    }
    EXPECT_GT(hi - lo, 0.02) << "texture kind " << k << " is flat: no features for ORB";
  }
}

TEST(Texture, SrgbToLinear) {
  EXPECT_FLOAT_EQ(srgb(255, 0, 255).x(), 1.0f);
  EXPECT_FLOAT_EQ(srgb(255, 0, 255).y(), 0.0f);
  EXPECT_NEAR(srgb(128, 128, 128).x(), std::pow(128.0f / 255.0f, 2.2f), 1e-6f);
}

}  // namespace rrg::synth
