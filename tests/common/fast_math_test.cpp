// floor_to_int, min_f / max_f and exp_neg (core/common/fast_math.h) against the C library on the host.
#include "core/common/fast_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <limits>

namespace rrg {
namespace {

TEST(FastMath, FloorToIntIsFloorOnKnownValues) {
  EXPECT_EQ(floor_to_int(0.0f), 0);
  EXPECT_EQ(floor_to_int(-0.0f), 0);
  EXPECT_EQ(floor_to_int(0.999f), 0);
  EXPECT_EQ(floor_to_int(1.0f), 1);
  EXPECT_EQ(floor_to_int(-1e-7f), -1);
  EXPECT_EQ(floor_to_int(-0.5f), -1);
  EXPECT_EQ(floor_to_int(-1.0f), -1);
  EXPECT_EQ(floor_to_int(-1.0001f), -2);
  EXPECT_EQ(floor_to_int(16777217.0f), 16777216);  // 2^24 + 1 rounds to 2^24 as a float
  EXPECT_EQ(floor_to_int(-3.5e8f), -350000000);
  EXPECT_EQ(floor_to_int(2.1e9f), 2100000000);
}

// Every float bit pattern in [-2^21, 2^21) along a coarse stride, and the neighbours of every
// integer in [-1000, 1000]: voxel and block coordinates of rooms far larger than any we map.
TEST(FastMath, FloorToIntMatchesFloorfOverTheVoxelRange) {
  int checked = 0;
  for (uint32_t bits = 0; bits < 0xFFFFFFFFu - 4099; bits += 4099) {
    float x;
    std::memcpy(&x, &bits, sizeof x);
    if (!(std::fabs(x) < 2097152.0f)) continue;
    ASSERT_EQ(floor_to_int(x), int(std::floor(x))) << x;
    ++checked;
  }
  for (int i = -1000; i <= 1000; ++i)
    for (const float x : {std::nextafter(float(i), -1e9f), float(i), std::nextafter(float(i), 1e9f)}) {
      ASSERT_EQ(floor_to_int(x), int(std::floor(x))) << x;
      ++checked;
    }
  EXPECT_GT(checked, 500000);
}

TEST(FastMath, MinMaxOfNumbers) {
  EXPECT_EQ(min_f(1.0f, 2.0f), 1.0f);
  EXPECT_EQ(min_f(-3.0f, -2.0f), -3.0f);
  EXPECT_EQ(max_f(1.0f, 2.0f), 2.0f);
  EXPECT_EQ(max_f(-3.0f, -2.0f), -2.0f);
  // NaN: the second operand, which is what the voxel codec relies on to clamp NaN into range
  // (voxel.h: encode_tsdf(NaN) = −1 as with fminf(fmaxf(NaN, −1), 1)).
  EXPECT_EQ(max_f(NAN, -1.0f), -1.0f);
  EXPECT_EQ(min_f(NAN, 1.0f), 1.0f);
}

// exp_neg against the double exponential over the range the Gaussian weights use: the splat
// falloff's [kPowerMin, 0] = [-5.54, 0] densely, the bilateral filter's down to the clamp.
TEST(FastMath, ExpNegIsWithinTwoUlpOfExp) {
  float worst = 0.0f;
  const auto check = [&](float x) {
    const double ref = std::exp(double(x));
    const double ulp = double(std::nextafter(float(ref), 2.0f) - float(ref));
    worst = std::max(worst, float(std::abs(double(exp_neg(x)) - ref) / ulp));
  };
  const int steps = 1 << 20;
  for (int i = 0; i <= steps; ++i) check(-5.5422645f * float(i) / float(steps));
  for (int i = 0; i <= steps; ++i) check(-87.0f * float(i) / float(steps));
  EXPECT_LE(worst, 2.0f);
  EXPECT_EQ(exp_neg(0.0f), 1.0f);
  EXPECT_NEAR(exp_neg(-1.0f), 0.36787944f, 1e-7f);
  EXPECT_GT(exp_neg(-87.0f), 0.0f);  // a normal float at the clamp
  EXPECT_EQ(exp_neg(-1000.0f), exp_neg(-87.0f));
  EXPECT_EQ(exp_neg(3.0f), 1.0f);    // x > 0 is clamped to 0
  std::printf("exp_neg: worst error %.2f ulp over [-87, 0]\n", worst);
}

// exp_clamped (the projection's exp(log s) and sigmoid) over its whole range [-87, 88], and the
// clamps at either end.
TEST(FastMath, ExpClampedIsWithinTwoUlpOfExp) {
  float worst = 0.0f;
  const int steps = 1 << 21;
  for (int i = 0; i <= steps; ++i) {
    const float x = -87.0f + 175.0f * float(i) / float(steps);
    const double ref = std::exp(double(x));
    const double ulp = double(std::nextafter(float(ref), INFINITY) - float(ref));
    worst = std::max(worst, float(std::abs(double(exp_clamped(x)) - ref) / ulp));
  }
  EXPECT_LE(worst, 2.0f);
  EXPECT_EQ(exp_clamped(0.0f), 1.0f);
  EXPECT_NEAR(exp_clamped(1.0f), 2.7182818f, 3e-7f);
  EXPECT_EQ(exp_clamped(-1000.0f), exp_clamped(-87.0f));
  EXPECT_EQ(exp_clamped(1000.0f), exp_clamped(88.0f));
  EXPECT_TRUE(std::isfinite(exp_clamped(88.0f)));
  EXPECT_GT(exp_clamped(88.0f), 1e38f);
  // the same polynomial as exp_neg where both apply
  for (const float x : {-80.0f, -5.0f, -0.3f, 0.0f}) EXPECT_EQ(exp_clamped(x), exp_neg(x));
  std::printf("exp_clamped: worst error %.2f ulp over [-87, 88]\n", worst);
}

// NaN in, NaN out, as expf: the clamps let NaN through, and vectorised loops compute lanes whose
// result is then discarded on NaN inputs (the bilateral filter's holes, a Gaussian without a
// covariance). The exponent arithmetic must be defined for it (unsigned; a UBSan build reported the
// signed product overflowing).
TEST(FastMath, ExpOfNaNIsNaN) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(std::isnan(exp_neg(nan)));
  EXPECT_TRUE(std::isnan(exp_clamped(nan)));
  EXPECT_TRUE(std::isnan(exp_reduced_host(nan)));
  EXPECT_TRUE(std::isnan(exp_reduced_host(-nan)));
}

}  // namespace
}  // namespace rrg
