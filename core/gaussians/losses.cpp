#include "core/gaussians/losses.h"

#include "core/common/dispatch.h"
#include "core/gaussians/losses_impl.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg {

namespace {

template <class A, class B>
void check_same(const A& a, const B& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height())
    throw std::invalid_argument(std::string(what) + ": images are " + std::to_string(a.width()) + "x" +
                                std::to_string(a.height()) + " and " + std::to_string(b.width()) + "x" +
                                std::to_string(b.height()));
  if (a.device() != b.device())
    throw std::invalid_argument(std::string(what) + ": images on " + a.device().to_string() + " and " +
                                b.device().to_string());
}

Span<const float> flat(const DeviceImage<Color>& im) {
  return {reinterpret_cast<const float*>(im.buffer().data()), int64_t(im.buffer().size()) * 3};
}
Span<float> flat_grad(DeviceImage<Color>* im) {
  if (!im) return {};
  return {reinterpret_cast<float*>(im->buffer().data()), int64_t(im->buffer().size()) * 3};
}
Span<const float> flat(const DeviceImage<float>& im) { return im.buffer().span(); }
Span<float> flat_grad(DeviceImage<float>* im) { return im ? im->buffer().span() : Span<float>{}; }

kernel::SsimWindow<float> make_window() {
  kernel::SsimWindow<float> w{};
  double g[2 * kernel::kSsimRadius + 1], sum = 0;
  for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) {
    const double d = k - kernel::kSsimRadius;
    g[k] = std::exp(-d * d / (2.0 * 1.5 * 1.5));
    sum += g[k];
  }
  for (int k = 0; k <= 2 * kernel::kSsimRadius; ++k) w.g[k] = float(g[k] / sum);
  w.c1 = 0.01f * 0.01f;
  w.c2 = 0.03f * 0.03f;
  return w;
}

template <class T>
void zero_like(DeviceImage<T>& out, int w, int h, const Device& device) {
  if (out.width() != w || out.height() != h || out.device() != device) out = DeviceImage<T>(w, h, device);
  out.fill_zero();
}

}  // namespace

void LossWeights::validate() const {
  auto check = [](float v, const char* name, float hi) {
    if (!(v >= 0.0f && v <= hi))
      throw std::invalid_argument(std::string("LossWeights: ") + name + " = " + std::to_string(v) +
                                  " outside [0, " + std::to_string(hi) + "]");
  };
  check(lambda_ssim, "lambda_ssim", 1.0f);
  check(lambda_depth, "lambda_depth", 1e6f);
  check(lambda_sobel, "lambda_sobel", 1e6f);
  check(lambda_reflective_base, "lambda_reflective_base", 1e6f);
}

float l1_loss(const DeviceImage<Color>& x, const DeviceImage<Color>& y, DeviceImage<Color>* v_x, float weight) {
  check_same(x, y, "l1_loss");
  if (v_x) check_same(x, *v_x, "l1_loss (gradient)");
  float r = 0;
  RRG_DISPATCH(x.device(), r = kernel::l1_loss_cpu<float>(flat(x), flat(y), flat_grad(v_x), weight),
               r = kernel::l1_loss_cuda(flat(x), flat(y), flat_grad(v_x), weight));
  return r;
}

float ssim(const DeviceImage<Color>& x, const DeviceImage<Color>& y, DeviceImage<Color>* v_x, float weight,
           Buffer<float>& scratch) {
  check_same(x, y, "ssim");
  if (v_x) check_same(x, *v_x, "ssim (gradient)");
  const size_t need = size_t(x.width()) * size_t(x.height()) * kernel::kSsimScratch;
  if (scratch.size() < need || scratch.device() != x.device()) scratch = Buffer<float>(need, x.device());
  const auto win = make_window();
  float r = 0;
  RRG_DISPATCH(x.device(),
               r = kernel::ssim_cpu<float>(x.width(), x.height(), flat(x), flat(y), flat_grad(v_x), weight, win,
                                           scratch.span()),
               r = kernel::ssim_cuda(x.width(), x.height(), flat(x), flat(y), flat_grad(v_x), weight, win,
                                     scratch.span()));
  return r;
}

float depth_l1_loss(const DeviceImage<float>& d, const DeviceImage<float>& d_gt, DeviceImage<float>* v_d,
                    float weight) {
  check_same(d, d_gt, "depth_l1_loss");
  if (v_d) check_same(d, *v_d, "depth_l1_loss (gradient)");
  float r = 0;
  RRG_DISPATCH(d.device(), r = kernel::depth_l1_loss_cpu<float>(flat(d), flat(d_gt), flat_grad(v_d), weight),
               r = kernel::depth_l1_loss_cuda(flat(d), flat(d_gt), flat_grad(v_d), weight));
  return r;
}

float sobel_l1_loss(const DeviceImage<Color>& x, DeviceImage<Color>* v_x, float weight, Buffer<int8_t>& scratch,
                    Buffer<float>& values) {
  if (v_x) check_same(x, *v_x, "sobel_l1_loss (gradient)");
  const size_t need = v_x ? size_t(x.width()) * size_t(x.height()) * 6 : 0;
  if (scratch.size() < need || (need > 0 && scratch.device() != x.device())) scratch = Buffer<int8_t>(need, x.device());
  const Span<int8_t> signs{scratch.data(), int64_t(need)};
  const size_t n = x.device().is_cpu() ? size_t(x.width()) * size_t(x.height()) * 3 : 0;
  if (values.size() < n || (n > 0 && values.device() != x.device())) values = Buffer<float>(n, x.device());
  float r = 0;
  RRG_DISPATCH(x.device(),
               r = kernel::sobel_l1_loss_cpu<float>(x.width(), x.height(), flat(x), flat_grad(v_x), weight, signs,
                                                    values.span()),
               r = kernel::sobel_l1_loss_cuda(x.width(), x.height(), flat(x), flat_grad(v_x), weight, signs));
  return r;
}

float reflective_base_prior(const DeviceImage<Color>& C_b, const DeviceImage<float>& R, DeviceImage<Color>* v_C,
                            DeviceImage<Color>* v_C_r, float weight) {
  check_same(C_b, R, "reflective_base_prior");
  if (bool(v_C) != bool(v_C_r))
    throw std::invalid_argument("reflective_base_prior: v_C and v_C_r are both given or both null");
  if (v_C) {
    check_same(C_b, *v_C, "reflective_base_prior (v_C)");
    check_same(C_b, *v_C_r, "reflective_base_prior (v_C_r)");
  }
  float r = 0;
  RRG_DISPATCH(C_b.device(),
               r = kernel::reflective_base_prior_cpu<float>(flat(C_b), flat(R), flat_grad(v_C), flat_grad(v_C_r), weight),
               r = kernel::reflective_base_prior_cuda(flat(C_b), flat(R), flat_grad(v_C), flat_grad(v_C_r), weight));
  return r;
}

LossValues mapping_loss(const DeviceImage<Color>& C, const DeviceImage<Color>& C_gt, const DeviceImage<float>& D_b,
                        const DeviceImage<float>& D_gt, const ReflectionImages* refl, const LossWeights& w,
                        DeviceImage<Color>& v_C, DeviceImage<float>& v_D_b, DeviceImage<Color>& v_C_r,
                        LossScratch& scratch) {
  w.validate();
  check_same(C, D_b, "mapping_loss (C, D_b)");
  const Device& dev = C.device();
  zero_like(v_C, C.width(), C.height(), dev);
  zero_like(v_D_b, C.width(), C.height(), dev);
  LossValues L;
  L.l1 = l1_loss(C, C_gt, &v_C, 1.0f - w.lambda_ssim);
  L.ssim = ssim(C, C_gt, &v_C, -w.lambda_ssim, scratch.ssim);  // ∂(λ(1 − SSIM)) = −λ ∂SSIM
  L.depth_l1 = depth_l1_loss(D_b, D_gt, &v_D_b, w.lambda_depth);
  if (refl && (w.lambda_sobel > 0.0f || w.lambda_reflective_base > 0.0f)) {
    check_same(C, refl->C_r, "mapping_loss (C, C_r)");
    zero_like(v_C_r, C.width(), C.height(), dev);
    if (w.lambda_sobel > 0.0f)
      L.sobel = sobel_l1_loss(refl->C_r, &v_C_r, w.lambda_sobel, scratch.sobel, scratch.sobel_values);
    if (w.lambda_reflective_base > 0.0f)
      L.reflective_base = reflective_base_prior(refl->C_b, refl->R, &v_C, &v_C_r, w.lambda_reflective_base);
  } else {
    v_C_r = DeviceImage<Color>();
  }
  L.total = (1.0 - w.lambda_ssim) * L.l1 + w.lambda_ssim * (1.0 - L.ssim) + w.lambda_depth * L.depth_l1 +
            w.lambda_sobel * L.sobel + w.lambda_reflective_base * L.reflective_base;
  return L;
}

}  // namespace rrg
