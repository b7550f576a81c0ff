#include "core/eval/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rrg::eval {
namespace {

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

void check_inputs(const ColorImage& est, const ColorImage& ref, const MaskImage* mask) {
  if (est.empty() || ref.empty()) throw std::invalid_argument("image metrics: empty image");
  if (!est.same_size(ref))
    throw std::invalid_argument("image metrics: estimated image is " + size_text(est.width(), est.height()) +
                                " but reference is " + size_text(ref.width(), ref.height()));
  if (mask && (mask->width() != ref.width() || mask->height() != ref.height()))
    throw std::invalid_argument("image metrics: mask is " + size_text(mask->width(), mask->height()) +
                                " but images are " + size_text(ref.width(), ref.height()));
}

bool included(const MaskImage* mask, size_t i) { return !mask || (*mask)[i] != 0; }

// Below this many pixels the filter runs on one thread: thread start-up would cost more.
constexpr size_t kParallelPixels = 1 << 14;

[[noreturn]] void throw_empty_mask() {
  throw std::invalid_argument("image metrics: mask includes no pixel");
}

// 'same' correlation of a W×H plane with g gᵀ, zero outside the image (separable: rows, then columns).
void gaussian_filter(const std::vector<double>& in, std::vector<double>& tmp, std::vector<double>& out,
                     int w, int h, const std::array<double, kSsimWindow>& g) {
  constexpr int r = kSsimWindow / 2;
#pragma omp parallel for schedule(static) if (size_t(w) * size_t(h) >= kParallelPixels)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k)
        if (x + k >= 0 && x + k < w) s += g[k + r] * in[size_t(y) * w + (x + k)];
      tmp[size_t(y) * w + x] = s;
    }
#pragma omp parallel for schedule(static) if (size_t(w) * size_t(h) >= kParallelPixels)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k)
        if (y + k >= 0 && y + k < h) s += g[k + r] * tmp[size_t(y + k) * w + x];
      out[size_t(y) * w + x] = s;
    }
}

}  // namespace

std::array<double, kSsimWindow> ssim_gaussian_1d() {
  std::array<double, kSsimWindow> g{};
  double sum = 0.0;
  for (int k = 0; k < kSsimWindow; ++k) {
    const double d = k - kSsimWindow / 2;
    g[k] = std::exp(-d * d / (2.0 * kSsimSigma * kSsimSigma));
    sum += g[k];
  }
  for (double& v : g) v /= sum;
  return g;
}

double mean_squared_error(const ColorImage& est, const ColorImage& ref, const MaskImage* mask) {
  check_inputs(est, ref, mask);
  double sum = 0.0;
  size_t count = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (!included(mask, i)) continue;
    sum += (est[i].cast<double>() - ref[i].cast<double>()).squaredNorm();
    count += 3;
  }
  if (count == 0) throw_empty_mask();
  return sum / double(count);
}

double psnr(const ColorImage& est, const ColorImage& ref, const MaskImage* mask) {
  const double mse = mean_squared_error(est, ref, mask);
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return -10.0 * std::log10(mse);  // 10·log10(1² / MSE)
}

std::vector<double> ssim_map(const ColorImage& est, const ColorImage& ref) {
  check_inputs(est, ref, nullptr);
  const int w = ref.width(), h = ref.height();
  const size_t n = ref.size();
  const auto g = ssim_gaussian_1d();
  std::vector<double> map(n * 3);
  std::vector<double> a(n), b(n), in(n), tmp(n), mu1(n), mu2(n), e11(n), e22(n), e12(n);
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < n; ++i) {
      a[i] = est[i][c];
      b[i] = ref[i][c];
    }
    gaussian_filter(a, tmp, mu1, w, h, g);
    gaussian_filter(b, tmp, mu2, w, h, g);
    for (size_t i = 0; i < n; ++i) in[i] = a[i] * a[i];
    gaussian_filter(in, tmp, e11, w, h, g);
    for (size_t i = 0; i < n; ++i) in[i] = b[i] * b[i];
    gaussian_filter(in, tmp, e22, w, h, g);
    for (size_t i = 0; i < n; ++i) in[i] = a[i] * b[i];
    gaussian_filter(in, tmp, e12, w, h, g);
    for (size_t i = 0; i < n; ++i) {
      const double mu1_sq = mu1[i] * mu1[i], mu2_sq = mu2[i] * mu2[i], mu1_mu2 = mu1[i] * mu2[i];
      const double sigma1_sq = e11[i] - mu1_sq, sigma2_sq = e22[i] - mu2_sq, sigma12 = e12[i] - mu1_mu2;
      map[i * 3 + c] = ((2.0 * mu1_mu2 + kSsimC1) * (2.0 * sigma12 + kSsimC2)) /
                       ((mu1_sq + mu2_sq + kSsimC1) * (sigma1_sq + sigma2_sq + kSsimC2));
    }
  }
  return map;
}

double ssim(const ColorImage& est, const ColorImage& ref, const MaskImage* mask) {
  check_inputs(est, ref, mask);
  if (mask && std::none_of(mask->pixels().begin(), mask->pixels().end(), [](uint8_t m) { return m != 0; }))
    throw_empty_mask();
  const std::vector<double> map = ssim_map(est, ref);
  double sum = 0.0;
  size_t count = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (!included(mask, i)) continue;
    sum += map[i * 3] + map[i * 3 + 1] + map[i * 3 + 2];
    count += 3;
  }
  return sum / double(count);
}

}  // namespace rrg::eval
