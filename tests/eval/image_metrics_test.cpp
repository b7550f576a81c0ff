// PSNR and SSIM against hand-computed values and a plain brute-force double-precision reference.
#include "core/eval/image_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rrg::eval {
namespace {

ColorImage random_image(int w, int h, uint64_t seed, float lo = 0.0f, float hi = 1.0f) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  ColorImage img(w, h);
  for (auto& c : img.pixels()) c = Color(u(rng), u(rng), u(rng));
  return img;
}

// The 3DGS window, written out independently: exp(−(k − 5)² / 4.5), normalised.
std::vector<double> window_1d() {
  std::vector<double> g(11);
  double sum = 0.0;
  for (int k = 0; k < 11; ++k) sum += g[k] = std::exp(-(k - 5.0) * (k - 5.0) / 4.5);
  for (double& v : g) v /= sum;
  return g;
}

TEST(Psnr, IdenticalImagesAreInfinite) {
  const ColorImage a = random_image(16, 9, 1);
  EXPECT_TRUE(std::isinf(psnr(a, a)));
  EXPECT_GT(psnr(a, a), 0.0);
}

TEST(Psnr, ConstantOffsetOfATenthIsTwentyDb) {
  // MSE = 0.1² = 0.01 ⇒ PSNR = −10·log10(0.01) = 20 dB. Float rounding of ref + 0.1 moves it < 1e-5 dB.
  const ColorImage ref = random_image(32, 24, 2, 0.0f, 0.8f);
  ColorImage est = ref;
  for (auto& c : est.pixels()) c += Color::Constant(0.1f);
  EXPECT_NEAR(psnr(est, ref), 20.0, 1e-5);
  EXPECT_NEAR(psnr(ref, est), 20.0, 1e-5);
}

TEST(Psnr, MaskSelectsPixels) {
  // Left half off by 0.1, right half by 0.2: whole image MSE = (0.01 + 0.04)/2 = 0.025 → 16.0206 dB.
  const ColorImage ref = random_image(20, 10, 3, 0.0f, 0.7f);
  ColorImage est = ref;
  MaskImage left(20, 10, 0);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 20; ++x) {
      est(x, y) += Color::Constant(x < 10 ? 0.1f : 0.2f);
      left(x, y) = x < 10 ? 255 : 0;
    }
  EXPECT_NEAR(psnr(est, ref), -10.0 * std::log10(0.025), 1e-5);
  EXPECT_NEAR(psnr(est, ref, &left), 20.0, 1e-5);
  EXPECT_NEAR(mean_squared_error(est, ref, &left), 0.01, 1e-8);
}

TEST(Ssim, WindowIsTheNormalisedGaussian) {
  const auto g = ssim_gaussian_1d();
  const auto expect = window_1d();
  for (int k = 0; k < 11; ++k) EXPECT_NEAR(g[k], expect[k], 1e-15);
  EXPECT_NEAR(g[5] / g[4], std::exp(1.0 / 4.5), 1e-13);
}

TEST(Ssim, IdenticalImagesGiveOne) {
  const ColorImage a = random_image(40, 30, 4);
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
}

TEST(Ssim, ConstantImagesMatchTheClosedFormIncludingZeroPaddedBorders) {
  // For constant images a and b, with w = Wx(x)·Wy(y) the window mass inside the image (zero
  // padding), the filtered maps are μ1 = a·w, μ2 = b·w, E[x²] = a²w, E[xy] = abw, so
  // σ1² = a²w(1 − w), σ2² = b²w(1 − w), σ12 = abw(1 − w) and
  // SSIM = (2abw² + C1)(2abw(1 − w) + C2) / (((a² + b²)w² + C1)((a² + b²)w(1 − w) + C2)).
  // In the interior (w = 1) this is (2ab + C1)/(a² + b² + C1).
  const int W = 20, H = 16;
  const Color ca(0.2f, 0.5f, 0.9f), cb(0.3f, 0.4f, 0.6f);
  const ColorImage a(W, H, ca), b(W, H, cb);
  const auto g = window_1d();
  auto mass = [&](int x, int n) {
    double m = 0.0;
    for (int k = -5; k <= 5; ++k)
      if (x + k >= 0 && x + k < n) m += g[k + 5];
    return m;
  };
  const double C1 = 1e-4, C2 = 9e-4;
  const std::vector<double> map = ssim_map(a, b);
  double sum = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        const double w = mass(x, W) * mass(y, H), A = ca[c], B = cb[c];
        const double expect = ((2 * A * B * w * w + C1) * (2 * A * B * w * (1 - w) + C2)) /
                              (((A * A + B * B) * w * w + C1) * ((A * A + B * B) * w * (1 - w) + C2));
        EXPECT_NEAR(map[(size_t(y) * W + x) * 3 + c], expect, 1e-9) << x << "," << y << " c" << c;
        sum += expect;
      }
  const double interior = (2 * 0.2 * 0.3 + C1) / (0.04 + 0.09 + C1);
  EXPECT_NEAR(map[(size_t(8) * W + 10) * 3], interior, 1e-7);  // (10, 8) is ≥ 5 px from every border
  EXPECT_NEAR(ssim(a, b), sum / (W * H * 3), 1e-9);
}

TEST(Ssim, MatchesBruteForceTwoDimensionalReference) {
  // Direct 11×11 zero-padded correlation in double, exactly as F.conv2d(padding=5), then the 3DGS formula.
  const int W = 23, H = 17;
  const ColorImage a = random_image(W, H, 5), b = random_image(W, H, 6);
  const auto g = window_1d();
  const double C1 = 1e-4, C2 = 9e-4;
  auto filt = [&](auto f, int x, int y) {
    double s = 0.0;
    for (int dy = -5; dy <= 5; ++dy)
      for (int dx = -5; dx <= 5; ++dx) {
        const int u = x + dx, v = y + dy;
        if (u >= 0 && u < W && v >= 0 && v < H) s += g[dx + 5] * g[dy + 5] * f(u, v);
      }
    return s;
  };
  MaskImage mask(W, H, 0);
  for (int y = 3; y < 12; ++y)
    for (int x = 0; x < 9; ++x) mask(x, y) = 1;
  const std::vector<double> map = ssim_map(a, b);
  double sum_all = 0.0, sum_masked = 0.0;
  int n_masked = 0;
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        auto A = [&](int u, int v) { return double(a(u, v)[c]); };
        auto B = [&](int u, int v) { return double(b(u, v)[c]); };
        const double mu1 = filt(A, x, y), mu2 = filt(B, x, y);
        const double s11 = filt([&](int u, int v) { return A(u, v) * A(u, v); }, x, y) - mu1 * mu1;
        const double s22 = filt([&](int u, int v) { return B(u, v) * B(u, v); }, x, y) - mu2 * mu2;
        const double s12 = filt([&](int u, int v) { return A(u, v) * B(u, v); }, x, y) - mu1 * mu2;
        const double v = ((2 * mu1 * mu2 + C1) * (2 * s12 + C2)) / ((mu1 * mu1 + mu2 * mu2 + C1) * (s11 + s22 + C2));
        ASSERT_NEAR(map[(size_t(y) * W + x) * 3 + c], v, 1e-10) << x << "," << y << " c" << c;
        sum_all += v;
        if (mask(x, y)) {
          sum_masked += v;
          ++n_masked;
        }
      }
  EXPECT_NEAR(ssim(a, b), sum_all / (W * H * 3), 1e-12);
  EXPECT_NEAR(ssim(a, b, &mask), sum_masked / n_masked, 1e-12);
  EXPECT_LT(ssim(a, b), 0.2);  // independent noise images are dissimilar
}

TEST(ImageMetrics, RejectMismatchedSizesAndEmptyMasks) {
  const ColorImage a = random_image(8, 8, 7), b = random_image(8, 9, 8);
  EXPECT_THROW(psnr(a, b), std::invalid_argument);
  EXPECT_THROW(ssim(a, b), std::invalid_argument);
  const MaskImage wrong(9, 8, 1), none(8, 8, 0);
  EXPECT_THROW(psnr(a, a, &wrong), std::invalid_argument);
  EXPECT_THROW(ssim(a, a, &none), std::invalid_argument);
  EXPECT_THROW(psnr(a, a, &none), std::invalid_argument);
  EXPECT_THROW(psnr(ColorImage{}, ColorImage{}), std::invalid_argument);
}

}  // namespace
}  // namespace rrg::eval
