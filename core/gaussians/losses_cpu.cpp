#include "core/common/parallel_for.h"
#include "core/gaussians/losses_impl.h"
#include "core/gaussians/ssim_rows_cpu.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace rrg::kernel {

template <class T>
T l1_loss_cpu(Span<const T> x, Span<const T> y, Span<T> v_x, T weight) {
  return l1_loss(CpuBackend{}, x, y, v_x, weight);
}
template <class T>
T depth_l1_loss_cpu(Span<const T> d, Span<const T> d_gt, Span<T> v_d, T weight) {
  return depth_l1_loss(CpuBackend{}, d, d_gt, v_d, weight);
}
template <class T>
T reflective_base_prior_cpu(Span<const T> C_b, Span<const T> R, Span<T> v_C, Span<T> v_C_r, T weight) {
  return reflective_base_prior(CpuBackend{}, C_b, R, v_C, v_C_r, weight);
}
// Streamed over rows (ssim_rows_cpu.h; the same floats as the separate passes) whenever its bands
// fit the scratch ssim() asks for, which is all but images a few rows tall.
template <class T>
T ssim_cpu(int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight, SsimWindow<T> win,
           Span<T> scratch) {
  const int64_t need = int64_t(w) * h * kSsimScratch;
  if (scratch.size < need)
    throw std::invalid_argument("ssim: the scratch holds " + std::to_string(scratch.size) + " scalars, " +
                                std::to_string(need) + " needed");
  if (w > 0 && h > 0 && ssim_rows_scratch(w, h, ssim_rows_bands(h)) <= need)
    return ssim_rows(w, h, x, y, v_x, weight, win, scratch);
  return ssim(CpuBackend{}, w, h, x, y, v_x, weight, win, scratch);
}
template <class T>
T sobel_l1_loss_cpu(int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs, Span<T> values) {
  const int64_t n = int64_t(std::max(w, 0)) * std::max(h, 0) * 3;
  std::vector<T> own;  // for callers without working memory (tests)
  if (values.size < n) {
    own.resize(size_t(n));
    values = {own.data(), n};
  }
  return sobel_l1_loss_rows(w, h, x, v_x, weight, signs, values);
}

#define RRG_LOSSES_INSTANTIATE(T)                                                                  \
  template T l1_loss_cpu<T>(Span<const T>, Span<const T>, Span<T>, T);                             \
  template T depth_l1_loss_cpu<T>(Span<const T>, Span<const T>, Span<T>, T);                       \
  template T reflective_base_prior_cpu<T>(Span<const T>, Span<const T>, Span<T>, Span<T>, T);      \
  template T ssim_cpu<T>(int, int, Span<const T>, Span<const T>, Span<T>, T, SsimWindow<T>, Span<T>); \
  template T sobel_l1_loss_cpu<T>(int, int, Span<const T>, Span<T>, T, Span<int8_t>, Span<T>);
RRG_LOSSES_INSTANTIATE(float)
RRG_LOSSES_INSTANTIATE(double)
#undef RRG_LOSSES_INSTANTIATE

}  // namespace rrg::kernel
