// Mapping losses: known answers, double-precision central finite differences of every gradient
// (the same kernels instantiated in double), float-vs-double agreement and CPU/CUDA parity.
#include "core/gaussians/losses.h"
#include "core/gaussians/losses_impl.h"
#include "core/gaussians/ssim_rows_cpu.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <vector>

namespace rrg {
namespace {

constexpr int W = 14, H = 12;

std::vector<double> random_image(int w, int h, int channels, uint32_t seed, double lo = 0.0, double hi = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> v(size_t(w) * h * channels);
  for (double& x : v) x = u(rng);
  return v;
}

kernel::SsimWindow<double> window_d() {
  kernel::SsimWindow<double> w{};
  double sum = 0;
  for (int k = 0; k < 11; ++k) sum += (w.g[k] = std::exp(-(k - 5.0) * (k - 5.0) / (2 * 1.5 * 1.5)));
  for (double& g : w.g) g /= sum;
  w.c1 = 1e-4;
  w.c2 = 9e-4;
  return w;
}

Span<const double> cs(const std::vector<double>& v) { return {v.data(), int64_t(v.size())}; }
Span<double> ms(std::vector<double>& v) { return {v.data(), int64_t(v.size())}; }

// Checks grad against central differences of f at every index; skip(i, h) lets piecewise-linear
// losses skip a scalar whose ±h straddles a kink. Returns the max error / max |grad|.
double fd_check(std::vector<double>& x, const std::vector<double>& grad, const std::function<double()>& f, double h,
                const std::function<bool(size_t)>& skip = {}) {
  double max_err = 0, max_g = 1e-30;
  size_t checked = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    max_g = std::max(max_g, std::abs(grad[i]));
    if (skip && skip(i)) continue;
    const double x0 = x[i];
    x[i] = x0 + h;
    const double fp = f();
    x[i] = x0 - h;
    const double fm = f();
    x[i] = x0;
    max_err = std::max(max_err, std::abs((fp - fm) / (2 * h) - grad[i]));
    ++checked;
  }
  EXPECT_GT(checked, x.size() / 2);
  return max_err / max_g;
}

TEST(Losses, L1KnownAnswerAndFiniteDifferences) {
  std::vector<double> x = random_image(W, H, 3, 1), y = random_image(W, H, 3, 2), g(x.size(), 0.0);
  std::vector<double> none;
  const double v = kernel::l1_loss_cpu<double>(cs(x), cs(y), ms(g), 0.7);
  double ref = 0;
  for (size_t i = 0; i < x.size(); ++i) ref += std::abs(x[i] - y[i]);
  EXPECT_NEAR(v, ref / double(x.size()), 1e-12);
  for (double& gi : g) gi /= 0.7;  // the gradient was added with weight 0.7
  const double h = 1e-6;
  const double err = fd_check(x, g, [&] { return kernel::l1_loss_cpu<double>(cs(x), cs(y), ms(none), 1.0); }, h,
                              [&](size_t i) { return std::abs(x[i] - y[i]) < 10 * h; });
  EXPECT_LT(err, 1e-6);
}

TEST(Losses, DepthL1IgnoresInvalidPixelsAndMatchesFiniteDifferences) {
  std::vector<double> d = random_image(W, H, 1, 3, 0.5, 4.0), gt = random_image(W, H, 1, 4, 0.5, 4.0);
  for (size_t i = 0; i < gt.size(); i += 3) gt[i] = 0.0;  // invalid
  std::vector<double> g(d.size(), 0.0), none;
  const double v = kernel::depth_l1_loss_cpu<double>(cs(d), cs(gt), ms(g), 1.0);
  double ref = 0, n = 0;
  for (size_t i = 0; i < d.size(); ++i)
    if (gt[i] > 0) ref += std::abs(d[i] - gt[i]), n += 1;
  EXPECT_NEAR(v, ref / n, 1e-12);
  for (size_t i = 0; i < gt.size(); i += 3) EXPECT_EQ(g[i], 0.0);
  const double err = fd_check(d, g, [&] { return kernel::depth_l1_loss_cpu<double>(cs(d), cs(gt), ms(none), 1.0); }, 1e-6,
                              [&](size_t i) { return gt[i] > 0 && std::abs(d[i] - gt[i]) < 1e-5; });
  EXPECT_LT(err, 1e-6);
  std::vector<double> all_invalid(d.size(), 0.0);
  EXPECT_EQ(kernel::depth_l1_loss_cpu<double>(cs(d), cs(all_invalid), ms(none), 1.0), 0.0);
}

TEST(Losses, SsimKnownAnswersAndFiniteDifferences) {
  std::vector<double> x = random_image(W, H, 3, 5), y = random_image(W, H, 3, 6);
  std::vector<double> scratch(size_t(W) * H * kernel::kSsimScratch), g(x.size(), 0.0), none;
  // SSIM(y, y) = 1 with a zero gradient (a maximum).
  std::vector<double> gy(x.size(), 0.0);
  EXPECT_NEAR(kernel::ssim_cpu<double>(W, H, cs(y), cs(y), ms(gy), 1.0, window_d(), ms(scratch)), 1.0, 1e-12);
  for (double v : gy) EXPECT_NEAR(v, 0.0, 1e-12);
  const double s = kernel::ssim_cpu<double>(W, H, cs(x), cs(y), ms(g), 1.0, window_d(), ms(scratch));
  EXPECT_LT(s, 0.5);  // independent noise images are far from similar
  const double err = fd_check(x, g, [&] {
    return kernel::ssim_cpu<double>(W, H, cs(x), cs(y), ms(none), 1.0, window_d(), ms(scratch));
  }, 1e-6);
  EXPECT_LT(err, 1e-6);
}

// The CPU runs each pass of the SSIM window tap by tap over whole rows (ssim_pass_row, vectorised);
// CUDA sums each element over its taps (ssim_tap_sum). Both add the same terms in the same order:
// the same floats bit for bit, in both directions, borders (zero padding) included.
TEST(Losses, SsimRowPassesEqualThePerElementTapSums) {
  const int w = 37, h = 23, C = 15;  // fewer than 11 columns/rows from a border on both sides
  std::vector<float> src(size_t(w) * h * C);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& v : src) v = u(rng);
  kernel::SsimWindow<float> win{};
  double total = 0;
  for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) total += std::exp(-(k - 5) * (k - 5) / 4.5);
  for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) win.g[k] = float(std::exp(-(k - 5) * (k - 5) / 4.5) / total);
  for (const bool vertical : {false, true}) {
    std::vector<float> rows(src.size());
    for (int y = 0; y < h; ++y) kernel::ssim_pass_row(src.data(), rows.data() + size_t(y) * w * C, w, h, C, vertical, y, win);
    int64_t differ = 0;
    for (int64_t i = 0; i < int64_t(src.size()); ++i) {
      const int pos = vertical ? int(i / C / w) : int(i / C % w);
      const float e = kernel::ssim_tap_sum(src.data(), i, pos, vertical ? h : w, vertical ? int64_t(w) * C : int64_t(C), win);
      differ += e == rows[size_t(i)] ? 0 : 1;
    }
    EXPECT_EQ(differ, 0) << (vertical ? "vertical" : "horizontal");
  }
}

// The CPU computes the Sobel term a row at a time (sobel_l1_loss_rows), CUDA one element at a time
// (sobel_l1_loss_elements): the same floats, value and gradient, borders and tiny images included.
TEST(Losses, SobelRowsEqualThePerElementSums) {
  for (auto [w, h] : {std::pair{37, 23}, std::pair{3, 3}, std::pair{4, 9}, std::pair{1100, 5}, std::pair{2, 7}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const size_t n = size_t(w) * h * 3;
    std::vector<float> x(n), g_rows(n, 0.5f), g_elems(n, 0.5f), values(n);
    std::mt19937 rng(w * 31 + h);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float& v : x) v = u(rng);
    for (size_t i = 0; i < n; i += 7) x[i] = x[i > 3 ? i - 3 : i];  // some responses exactly 0 (sign 0)
    std::vector<int8_t> s_rows(2 * n, 9), s_elems(2 * n, 9);
    const Span<const float> xs{x.data(), int64_t(n)};
    const float a = kernel::sobel_l1_loss_rows<float>(w, h, xs, {g_rows.data(), int64_t(n)}, 0.3f,
                                                      {s_rows.data(), int64_t(2 * n)}, {values.data(), int64_t(n)});
    const float b = kernel::sobel_l1_loss_elements<CpuBackend, float>(
        CpuBackend{}, w, h, xs, {g_elems.data(), int64_t(n)}, 0.3f, {s_elems.data(), int64_t(2 * n)});
    EXPECT_EQ(a, b);
    int64_t differ = 0;
    for (size_t i = 0; i < n; ++i) differ += g_rows[i] == g_elems[i] ? 0 : 1;
    EXPECT_EQ(differ, 0);
    if (w >= 3 && h >= 3) EXPECT_GT(a, 0.0f);
  }
}

// The CPU's SSIM streams rows through rings (ssim_rows) instead of whole intermediate images: the
// same floats as the separate passes, value and gradient, at sizes from under one window to several
// bands (the bands recompute their neighbours' halo rows), with and without the gradient.
TEST(Losses, SsimRowsEqualTheSeparatePasses) {
  for (auto [w, h] : {std::pair{37, 23}, std::pair{8, 5}, std::pair{300, 97}, std::pair{5, 140}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const size_t n = size_t(w) * h * 3;
    std::vector<float> x(n), y(n), g_rows(n, 0.25f), g_sep(n, 0.25f);
    std::mt19937 rng(w + 1000 * h);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t i = 0; i < n; ++i) x[i] = u(rng), y[i] = 0.5f * x[i] + 0.5f * u(rng);
    std::vector<float> scratch(size_t(w) * h * kernel::kSsimScratch);
    const Span<float> sc{scratch.data(), int64_t(scratch.size())};
    const Span<const float> xs{x.data(), int64_t(n)}, ys{y.data(), int64_t(n)};
    kernel::SsimWindow<float> win{};
    double total = 0;
    for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) total += std::exp(-(k - 5) * (k - 5) / 4.5);
    for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) win.g[k] = float(std::exp(-(k - 5) * (k - 5) / 4.5) / total);
    win.c1 = 1e-4f, win.c2 = 9e-4f;
    ASSERT_LE(kernel::ssim_rows_scratch(w, h, kernel::ssim_rows_bands(h)), int64_t(scratch.size()));
    for (const bool grad : {false, true}) {
      const Span<float> g_r = grad ? Span<float>{g_rows.data(), int64_t(n)} : Span<float>{};
      const Span<float> g_s = grad ? Span<float>{g_sep.data(), int64_t(n)} : Span<float>{};
      const float a = kernel::ssim_rows<float>(w, h, xs, ys, g_r, -0.2f, win, sc);
      const float b = kernel::ssim<CpuBackend, float>(CpuBackend{}, w, h, xs, ys, g_s, -0.2f, win, sc);
      EXPECT_EQ(a, b) << (grad ? "with" : "without") << " the gradient";
      EXPECT_GT(a, 0.0f);
    }
    int64_t differ = 0;
    for (size_t i = 0; i < n; ++i) differ += g_rows[i] == g_sep[i] ? 0 : 1;
    EXPECT_EQ(differ, 0);
    EXPECT_NE(g_rows[n / 2], 0.25f);  // the gradient was added
  }
}

TEST(Losses, SsimRefusesAScratchTooSmall) {
  std::vector<double> x = random_image(W, H, 3, 5), y = random_image(W, H, 3, 6), none;
  std::vector<double> scratch(size_t(W) * H * kernel::kSsimScratch - 1);
  EXPECT_THROW(kernel::ssim_cpu<double>(W, H, cs(x), cs(y), ms(none), 1.0, window_d(), ms(scratch)), std::invalid_argument);
}

TEST(Losses, SobelKnownAnswerAndFiniteDifferences) {
  // A ramp I = a x in every channel: Gx = 8a, Gy = 0 everywhere inside.
  std::vector<double> ramp(size_t(W) * H * 3), none;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) ramp[(size_t(y) * W + x) * 3 + c] = 0.05 * x;
  std::vector<int8_t> signs(size_t(W) * H * 6), no_signs;
  const Span<int8_t> sg{signs.data(), int64_t(signs.size())}, no_sg{no_signs.data(), 0};
  EXPECT_NEAR(kernel::sobel_l1_loss_cpu<double>(W, H, cs(ramp), ms(none), 1.0, no_sg), 8 * 0.05, 1e-12);
  std::vector<double> x = random_image(W, H, 3, 7), g(x.size(), 0.0);
  kernel::sobel_l1_loss_cpu<double>(W, H, cs(x), ms(g), 1.0, sg);
  // A step of h moves a response by at most 4h: random data puts none that close to the kink at 0.
  const double err =
      fd_check(x, g, [&] { return kernel::sobel_l1_loss_cpu<double>(W, H, cs(x), ms(none), 1.0, no_sg); }, 1e-7);
  EXPECT_LT(err, 1e-6);
}

ColorImage to_color(const std::vector<double>& v, int w, int h) {
  ColorImage im(w, h);
  for (size_t i = 0; i < im.size(); ++i) im[i] = Color(float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2]));
  return im;
}

// The float API (what the mapper runs) agrees with the double kernels, on every device.
TEST(Losses, FloatApiMatchesDoubleAndDevicesAgree) {
  const std::vector<double> xd = random_image(W, H, 3, 8), yd = random_image(W, H, 3, 9), rd = random_image(W, H, 3, 10);
  const std::vector<double> dd = random_image(W, H, 1, 11, 1, 3), gtd = random_image(W, H, 1, 12, 1, 3);
  // double reference of the whole loss and its gradients
  std::vector<double> scratch(size_t(W) * H * kernel::kSsimScratch), vC(xd.size(), 0.0), vD(dd.size(), 0.0), vR(rd.size(), 0.0);
  const double l1 = kernel::l1_loss_cpu<double>(cs(xd), cs(yd), ms(vC), 0.8);
  const double ss = kernel::ssim_cpu<double>(W, H, cs(xd), cs(yd), ms(vC), -0.2, window_d(), ms(scratch));
  const double dl = kernel::depth_l1_loss_cpu<double>(cs(dd), cs(gtd), ms(vD), 0.2);
  std::vector<int8_t> signs(size_t(W) * H * 6);
  const double sb = kernel::sobel_l1_loss_cpu<double>(W, H, cs(rd), ms(vR), 0.05, {signs.data(), int64_t(signs.size())});
  // λ_rb's term: C_b random, R a 0 / 1 mask with both values
  const std::vector<double> bd = random_image(W, H, 3, 13);
  std::vector<double> md(size_t(W) * H);
  for (size_t i = 0; i < md.size(); ++i) md[i] = (i * 7919 % 5) < 3 ? 1.0 : 0.0;
  const double rb = kernel::reflective_base_prior_cpu<double>(cs(bd), cs(md), ms(vC), ms(vR), 0.3);
  const double total = 0.8 * l1 + 0.2 * (1 - ss) + 0.2 * dl + 0.05 * sb + 0.3 * rb;

  const ColorImage X = to_color(xd, W, H), Y = to_color(yd, W, H), Rr = to_color(rd, W, H), B = to_color(bd, W, H);
  Image<float> M(W, H);
  for (size_t i = 0; i < M.size(); ++i) M[i] = float(md[i]);
  DepthImage D(W, H), G(W, H);
  for (size_t i = 0; i < D.size(); ++i) D[i] = float(dd[i]), G[i] = float(gtd[i]);
  const auto got = test::expect_device_parity<double>(
      [&](const Device& dev) {
        const auto C = DeviceImage<Color>::from_host(X, dev), Cgt = DeviceImage<Color>::from_host(Y, dev);
        const auto Cr = DeviceImage<Color>::from_host(Rr, dev), Cb = DeviceImage<Color>::from_host(B, dev);
        const auto Rm = DeviceImage<float>::from_host(M, dev);
        const auto Db = DeviceImage<float>::from_host(D, dev), Dgt = DeviceImage<float>::from_host(G, dev);
        DeviceImage<Color> v_C, v_Cr;
        DeviceImage<float> v_D;
        LossScratch sc;
        const ReflectionImages refl{Cr, Cb, Rm};
        const LossValues L = mapping_loss(C, Cgt, Db, Dgt, &refl, LossWeights{}, v_C, v_D, v_Cr, sc);
        std::vector<double> out = {L.total, L.l1, L.ssim, L.depth_l1, L.sobel, L.reflective_base};
        const ColorImage hC = v_C.to_host(), hCr = v_Cr.to_host();
        const DepthImage hD = v_D.to_host();
        for (const Color& c : hC.pixels()) out.insert(out.end(), {c.x(), c.y(), c.z()});
        for (float v : hD.pixels()) out.push_back(v);
        for (const Color& c : hCr.pixels()) out.insert(out.end(), {c.x(), c.y(), c.z()});
        return out;
      },
      1e-6, 1e-4);
  EXPECT_NEAR(got[0], total, 1e-5);
  EXPECT_NEAR(got[1], l1, 1e-6);
  EXPECT_NEAR(got[2], ss, 1e-5);
  EXPECT_NEAR(got[3], dl, 1e-6);
  EXPECT_NEAR(got[4], sb, 1e-5);
  EXPECT_NEAR(got[5], rb, 1e-6);
  EXPECT_GT(rb, 0.1);  // the term is on in the default weights and sees the mask
  size_t k = 6;
  double max_g = 0, max_err = 0;
  for (const auto* ref : {&vC, &vD, &vR})
    for (double r : *ref) {
      max_g = std::max(max_g, std::abs(r));
      max_err = std::max(max_err, std::abs(got[k++] - r));
    }
  EXPECT_EQ(k, got.size());
  EXPECT_LT(max_err, 1e-4 * max_g);
}

// λ_rb's term by hand: C_b = 0.4 everywhere, R = 1 on the left half of a 4x2 image: mean(R · C_b)
// = 0.2; its gradient goes into v_C as +s R and into v_C_r as −s R (s = weight / 24), which the
// renderer turns into s R on C_b and nothing on C_r (RenderGradient.ReflectiveBasePriorReachesTheBaseOnly).
TEST(Losses, ReflectiveBasePriorKnownAnswer) {
  ColorImage cb(4, 2);
  Image<float> r(4, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) cb(x, y) = Color::Constant(0.4f), r(x, y) = x < 2 ? 1.0f : 0.0f;
  const auto Cb = DeviceImage<Color>::from_host(cb, Device::cpu());
  const auto R = DeviceImage<float>::from_host(r, Device::cpu());
  auto v_C = DeviceImage<Color>::from_host(ColorImage(4, 2, Color::Constant(0.5f)), Device::cpu());
  auto v_Cr = DeviceImage<Color>::from_host(ColorImage(4, 2, Color::Constant(0.25f)), Device::cpu());
  EXPECT_NEAR(reflective_base_prior(Cb, R, nullptr, nullptr, 0.3f), 0.2f, 1e-7f);
  EXPECT_NEAR(reflective_base_prior(Cb, R, &v_C, &v_Cr, 0.3f), 0.2f, 1e-7f);
  const ColorImage hC = v_C.to_host(), hCr = v_Cr.to_host();
  const float s = 0.3f / 24.0f;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(hC(x, y)[c], x < 2 ? 0.5f + s : 0.5f);  // added to what the other terms left
        EXPECT_FLOAT_EQ(hCr(x, y)[c], x < 2 ? 0.25f - s : 0.25f);
      }
  EXPECT_THROW(reflective_base_prior(Cb, R, &v_C, nullptr, 0.3f), std::invalid_argument);
  const auto R_small = DeviceImage<float>::from_host(Image<float>(3, 2), Device::cpu());
  EXPECT_THROW(reflective_base_prior(Cb, R_small, nullptr, nullptr, 0.3f), std::invalid_argument);
  LossWeights w;
  w.lambda_reflective_base = -0.1f;
  EXPECT_THROW(w.validate(), std::invalid_argument);
}

TEST(Losses, RejectsMismatchedImages) {
  const auto a = DeviceImage<Color>::from_host(ColorImage(4, 4), Device::cpu());
  const auto b = DeviceImage<Color>::from_host(ColorImage(5, 4), Device::cpu());
  EXPECT_THROW(l1_loss(a, b, nullptr, 1.0f), std::invalid_argument);
  LossWeights w;
  w.lambda_ssim = 2.0f;
  EXPECT_THROW(w.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rrg
