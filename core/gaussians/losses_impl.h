#pragma once
// Bodies of the mapping losses (losses.h), templated on the back end and the scalar; instantiated
// by losses_cpu.cpp (float and double) and losses_cuda.cu (float). Images are interleaved RGB
// ([H, W, 3] scalars) or single-channel depth. Each function returns the loss value and, when v_x
// is not empty, ADDS weight · ∂loss/∂x to v_x, so several terms share one upstream image.
#include "core/common/span.h"
#include "core/gaussians/losses_device.h"

#include <cstdint>

namespace rrg::kernel {

template <class T>
struct SumCount {
  T sum, count;
};

// L1 = mean_i |x_i − y_i| over all pixels and channels.
template <class Backend, class T>
T l1_loss(Backend be, Span<const T> x, Span<const T> y, Span<T> v_x, T weight) {
  const int64_t n = x.size;
  const T total = parallel_reduce(
      be, n, T(0), [=] RRG_HD(int64_t i) { return abs_of(x[i] - y[i]); },
      [] RRG_HD(T a, T b) { return a + b; });
  if (!v_x.empty()) {
    const T s = weight / T(n);
    parallel_for(be, n, [=] RRG_HD(int64_t i) { v_x[i] += s * sign_of(x[i] - y[i]); });
  }
  return total / T(n);
}

// L_depth = mean over pixels with D_gt > 0 of |D − D_gt| (0 when no pixel is valid).
template <class Backend, class T>
T depth_l1_loss(Backend be, Span<const T> d, Span<const T> d_gt, Span<T> v_d, T weight) {
  const SumCount<T> sc = parallel_reduce(
      be, d.size, SumCount<T>{T(0), T(0)},
      [=] RRG_HD(int64_t i) {
        return d_gt[i] > T(0) ? SumCount<T>{abs_of(d[i] - d_gt[i]), T(1)} : SumCount<T>{T(0), T(0)};
      },
      [] RRG_HD(SumCount<T> a, SumCount<T> b) { return SumCount<T>{a.sum + b.sum, a.count + b.count}; });
  if (sc.count == T(0)) return T(0);
  if (!v_d.empty()) {
    const T s = weight / sc.count;
    parallel_for(be, d.size, [=] RRG_HD(int64_t i) {
      if (d_gt[i] > T(0)) v_d[i] += s * sign_of(d[i] - d_gt[i]);
    });
  }
  return sc.sum / sc.count;
}

// s[ch][m] = Σ_k g(k) src[(q_k · 3 + ch) · M + m] over the SSIM window around pixel p along one axis
// (q_k = p + k, or p + k · w when vertical), clipped at the image border (zero padding): one
// separable pass over M stored moments per channel, taps in ascending k.
template <int M, class T>
RRG_HD inline void ssim_window_sum(const T* src, int64_t p, int w, int h, bool vertical, const SsimWindow<T>& win,
                                   T (&s)[3][M]) {
  constexpr int R = kSsimRadius;
  const int pos = vertical ? int(p / w) : int(p % w), len = vertical ? h : w;
  const int k0 = pos - R < 0 ? -pos : -R, k1 = pos + R >= len ? len - 1 - pos : R;
  const int64_t step = vertical ? w : 1;
  for (int ch = 0; ch < 3; ++ch)
    for (int m = 0; m < M; ++m) s[ch][m] = T(0);
  for (int k = -R; k <= R; ++k) {
    if (k < k0 || k > k1) continue;
    const int64_t j = (p + k * step) * 3;
    const T g = win.g[k + R];
    for (int ch = 0; ch < 3; ++ch)
      for (int m = 0; m < M; ++m) s[ch][m] += g * src[(j + ch) * M + m];
  }
}

// SSIM = mean over pixels and channels of the SSIM map (3DGS: 11×11 Gaussian window, σ = 1.5, zero
// padding). Separable windowed sums; scratch holds 36 · W · H scalars. The gradient uses
// ∂SSIM_mean/∂x_q = 1/(3N) Σ_p g(p−q) [a(p) + 2 x_q b(p) + y_q c(p)]
//                 = 1/(3N) [(g⋆a)(q) + 2 x_q (g⋆b)(q) + y_q (g⋆c)(q)]  (the window is symmetric).
template <class Backend, class T>
T ssim(Backend be, int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight,
       SsimWindow<T> win, Span<T> scratch) {
  const int64_t n = int64_t(w) * h;  // pixels
  T* hm = scratch.data;              // [N, 3, 5] horizontal sums of x, y, x², y², xy
  T* abc = hm + n * 15;              // [N, 3, 3] a, b, c
  T* hs = abc + n * 9;               // [N, 3, 3] horizontal sums of a, b, c
  T* smap = hs + n * 9;              // [N, 3] SSIM map
  constexpr int R = kSsimRadius;
  // One work item per pixel, its three channels together: the window's bounds and the index math
  // are done once per pixel. Per channel the sums run over the taps in the same order as a loop per
  // channel would, so the result does not depend on this grouping.
  parallel_for(be, n, [=] RRG_HD(int64_t p) {
    const int px = int(p % w), py = int(p / w);
    const int k0 = px - R < 0 ? -px : -R, k1 = px + R >= w ? w - 1 - px : R;
    T s[3][5] = {};
    for (int k = -R; k <= R; ++k) {
      if (k < k0 || k > k1) continue;
      const int64_t j = (int64_t(py) * w + px + k) * 3;
      const T g = win.g[k + R];
      for (int ch = 0; ch < 3; ++ch) {
        const T a = x[j + ch], b = y[j + ch];
        s[ch][0] += g * a; s[ch][1] += g * b; s[ch][2] += g * a * a; s[ch][3] += g * b * b; s[ch][4] += g * a * b;
      }
    }
    for (int ch = 0; ch < 3; ++ch)
      for (int m = 0; m < 5; ++m) hm[(p * 3 + ch) * 5 + m] = s[ch][m];
  });
  parallel_for(be, n, [=] RRG_HD(int64_t p) {
    T s[3][5];
    ssim_window_sum<5>(hm, p, w, h, true, win, s);
    for (int ch = 0; ch < 3; ++ch) {
      const int64_t i = p * 3 + ch;
      T a, b, c;
      smap[i] = ssim_from_moments(s[ch][0], s[ch][1], s[ch][2], s[ch][3], s[ch][4], win.c1, win.c2, &a, &b, &c);
      abc[i * 3 + 0] = a; abc[i * 3 + 1] = b; abc[i * 3 + 2] = c;
    }
  });
  const T total = parallel_reduce(
      be, n * 3, T(0), [=] RRG_HD(int64_t i) { return smap[i]; }, [] RRG_HD(T a, T b) { return a + b; });
  if (!v_x.empty()) {
    parallel_for(be, n, [=] RRG_HD(int64_t p) {
      T s[3][3];
      ssim_window_sum<3>(abc, p, w, h, false, win, s);
      for (int ch = 0; ch < 3; ++ch)
        for (int m = 0; m < 3; ++m) hs[(p * 3 + ch) * 3 + m] = s[ch][m];
    });
    const T scale = weight / T(n * 3);
    parallel_for(be, n, [=] RRG_HD(int64_t p) {
      T s[3][3];
      ssim_window_sum<3>(hs, p, w, h, true, win, s);
      for (int ch = 0; ch < 3; ++ch) {
        const int64_t i = p * 3 + ch;
        v_x[i] += scale * (s[ch][0] + T(2) * x[i] * s[ch][1] + y[i] * s[ch][2]);
      }
    });
  }
  return total / T(n * 3);
}

// L_grad = ‖Sobel(C_r)‖₁ = mean over interior pixels (1 ≤ x ≤ W−2, 1 ≤ y ≤ H−2) and channels of
// |Gx| + |Gy|. Gradient gathered per pixel q from the 3×3 interior neighbours p:
// Σ_p sign(Gx(p)) kx(q − p) + sign(Gy(p)) ky(q − p).
template <class Backend, class T>
T sobel_l1_loss(Backend be, int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs) {
  if (w < 3 || h < 3) return T(0);
  const T count = T(int64_t(w - 2) * (h - 2) * 3);
  const T* img = x.data;
  const bool grad = !v_x.empty();
  // With the gradient, the forward pass keeps sign(Gx), sign(Gy) of every interior element in
  // `signs` ([2 w h 3]): the backward reads the nine responses around each element from there
  // instead of recomputing each 3x3 Sobel nine times (the same values, so the same sums).
  const T total = parallel_reduce(
      be, int64_t(w) * h * 3, T(0),
      [=] RRG_HD(int64_t i) {
        const int64_t p = i / 3;
        const int ch = int(i % 3), px = int(p % w), py = int(p / w);
        if (px < 1 || py < 1 || px > w - 2 || py > h - 2) return T(0);
        T gx, gy;
        sobel_at(img, w, px, py, ch, &gx, &gy);
        if (grad) {
          signs[2 * i] = int8_t(sign_of(gx));
          signs[2 * i + 1] = int8_t(sign_of(gy));
        }
        return abs_of(gx) + abs_of(gy);
      },
      [] RRG_HD(T a, T b) { return a + b; });
  if (grad) {
    const T s = weight / count;
    parallel_for(be, int64_t(w) * h * 3, [=] RRG_HD(int64_t i) {
      const int64_t q = i / 3;
      const int ch = int(i % 3), qx = int(q % w), qy = int(q / w);
      T g = T(0);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int px = qx - dx, py = qy - dy;  // q = p + (dx, dy)
          if (px < 1 || py < 1 || px > w - 2 || py > h - 2) continue;
          const int64_t j = (int64_t(py) * w + px) * 3 + ch;
          g += T(signs[2 * j]) * T(sobel_kx(dx, dy)) + T(signs[2 * j + 1]) * T(sobel_ky(dx, dy));
        }
      v_x[i] += s * g;
    });
  }
  return total / count;
}

// Entry points of each back end (T = float everywhere; T = double on the CPU for the tests).
template <class T>
T l1_loss_cpu(Span<const T> x, Span<const T> y, Span<T> v_x, T weight);
template <class T>
T depth_l1_loss_cpu(Span<const T> d, Span<const T> d_gt, Span<T> v_d, T weight);
template <class T>
T ssim_cpu(int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight, SsimWindow<T> win,
           Span<T> scratch);
template <class T>
T sobel_l1_loss_cpu(int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs);

float l1_loss_cuda(Span<const float> x, Span<const float> y, Span<float> v_x, float weight);
float depth_l1_loss_cuda(Span<const float> d, Span<const float> d_gt, Span<float> v_d, float weight);
float ssim_cuda(int w, int h, Span<const float> x, Span<const float> y, Span<float> v_x, float weight,
                SsimWindow<float> win, Span<float> scratch);
float sobel_l1_loss_cuda(int w, int h, Span<const float> x, Span<float> v_x, float weight, Span<int8_t> signs);

}  // namespace rrg::kernel
