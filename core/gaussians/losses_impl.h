#pragma once
// Bodies of the mapping losses (losses.h), templated on the back end and the scalar; instantiated
// by losses_cpu.cpp (float and double) and losses_cuda.cu (float). Images are interleaved RGB
// ([H, W, 3] scalars) or single-channel depth. Each function returns the loss value and, when v_x
// is not empty, ADDS weight · ∂loss/∂x to v_x, so several terms share one upstream image.
#include "core/common/parallel_for.h"
#include "core/common/span.h"
#include "core/gaussians/losses_device.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>

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

// L_rb = mean over pixels and channels of R · C_b (ours, docs/mapping.md "The base under a
// reflection"), R the 0/1 reflection mask. Its gradient reaches C_b only: the renderer hands v_C to
// C_b and R v_C (+ v_C_r) to C_r (C = C_b + R C_r), so adding s R to v_C and −s R to v_C_r gives
// C_b the gradient s R and C_r s (R² − R) = 0, exact for R in {0, 1}.
template <class Backend, class T>
T reflective_base_prior(Backend be, Span<const T> C_b, Span<const T> R, Span<T> v_C, Span<T> v_C_r, T weight) {
  const int64_t n = C_b.size;  // pixels × 3
  const T total = parallel_reduce(
      be, n, T(0), [=] RRG_HD(int64_t i) { return R[i / 3] * C_b[i]; }, [] RRG_HD(T a, T b) { return a + b; });
  if (!v_C.empty()) {
    const T s = weight / T(n);
    parallel_for(be, n, [=] RRG_HD(int64_t i) {
      const T g = s * R[i / 3];
      v_C[i] += g;
      v_C_r[i] -= g;
    });
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

// One separable pass of the SSIM window over an array of C values per pixel ([H, W, C]): value e
// of pixel p gets Σ_k g(k) src[(q_k · C) + e] with q_k = p + k (horizontal) or p + k · w (vertical),
// over the taps whose pixel lies in the image (zero padding), in ascending k. This is the sum of one
// element (CUDA: one thread each); the CPU runs the same sums tap by tap over whole rows
// (ssim_pass_rows), which adds the same terms to each element in the same order.
template <class T>
RRG_HD inline T ssim_tap_sum(const T* src, int64_t i, int pos, int len, int64_t step, const SsimWindow<T>& win) {
  constexpr int R = kSsimRadius;
  const int k0 = pos - R < 0 ? -pos : -R, k1 = pos + R >= len ? len - 1 - pos : R;
  T s = T(0);
  for (int k = k0; k <= k1; ++k) s += win.g[k + R] * src[i + k * step];
  return s;
}

// Row y of a pass (C values per pixel) into out[0, w · C): for each tap k, the elements whose tap
// pixel is inside form one contiguous run, so the inner loop is a plain vectorised axpy.
template <class T>
inline void ssim_pass_row(const T* src, T* out, int w, int h, int C, bool vertical, int y, const SsimWindow<T>& win) {
  constexpr int R = kSsimRadius;
  const int64_t row = int64_t(w) * C;
  std::fill(out, out + row, T(0));
  for (int k = -R; k <= R; ++k) {
    const T g = win.g[k + R];
    if (vertical) {
      if (y + k < 0 || y + k >= h) continue;
      const T* s = src + int64_t(y + k) * row;
      for (int64_t e = 0; e < row; ++e) out[e] += g * s[e];
    } else {
      const int x0 = k < 0 ? -k : 0, x1 = k > 0 ? w - k : w;
      if (x0 >= x1) continue;
      const T* s = src + int64_t(y) * row + int64_t(k) * C;
      for (int64_t e = int64_t(x0) * C; e < int64_t(x1) * C; ++e) out[e] += g * s[e];
    }
  }
}

// The two passes of the window over C values per pixel: src -> mid (horizontal) -> out (vertical).
template <class Backend, class T>
void ssim_window(Backend be, int w, int h, int C, const T* src, T* mid, T* out, const SsimWindow<T>& win) {
  const int64_t n = int64_t(w) * h;
  if constexpr (std::is_same_v<Backend, CpuBackend>) {
    parallel_for(be, h, [=](int64_t row) { ssim_pass_row(src, mid + row * w * C, w, h, C, false, int(row), win); });
    parallel_for(be, h, [=](int64_t row) { ssim_pass_row(mid, out + row * w * C, w, h, C, true, int(row), win); });
  } else {
    parallel_for(be, n * C, [=] RRG_HD(int64_t i) { mid[i] = ssim_tap_sum(src, i, int((i / C) % w), w, int64_t(C), win); });
    parallel_for(be, n * C, [=] RRG_HD(int64_t i) {
      out[i] = ssim_tap_sum(mid, i, int((i / C) / w), h, int64_t(w) * C, win);
    });
  }
}

// SSIM = mean over pixels and channels of the SSIM map (3DGS: 11×11 Gaussian window, σ = 1.5, zero
// padding). Separable windowed sums; scratch holds kSsimScratch · W · H scalars. The gradient uses
// ∂SSIM_mean/∂x_q = 1/(3N) Σ_p g(p−q) [a(p) + 2 x_q b(p) + y_q c(p)]
//                 = 1/(3N) [(g⋆a)(q) + 2 x_q (g⋆b)(q) + y_q (g⋆c)(q)]  (the window is symmetric).
// Per pixel and channel the values are the moments x, y, x², y², xy (5), then a, b, c (3).
inline constexpr int kSsimScratch = 15 + 15 + 15 + 9 + 9 + 9 + 3;

template <class Backend, class T>
T ssim(Backend be, int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight,
       SsimWindow<T> win, Span<T> scratch) {
  const int64_t n = int64_t(w) * h;  // pixels
  if (scratch.size < n * kSsimScratch)
    throw std::invalid_argument("ssim: the scratch holds " + std::to_string(scratch.size) + " scalars, " +
                                std::to_string(n * kSsimScratch) + " needed");
  T* mom = scratch.data;             // [N, 3, 5] x, y, x², y², xy
  T* hm = mom + n * 15;              // [N, 3, 5] their horizontal sums
  T* vm = hm + n * 15;               // [N, 3, 5] then vertical: the windowed moments
  T* abc = vm + n * 15;              // [N, 3, 3] a, b, c
  T* hs = abc + n * 9;               // [N, 3, 3] horizontal sums of a, b, c
  T* vs = hs + n * 9;                // [N, 3, 3] then vertical
  T* smap = vs + n * 9;              // [N, 3] SSIM map
  parallel_for(be, n * 3, [=] RRG_HD(int64_t i) {
    const T a = x[i], b = y[i];
    T* m = mom + i * 5;
    m[0] = a, m[1] = b, m[2] = a * a, m[3] = b * b, m[4] = a * b;
  });
  ssim_window(be, w, h, 15, mom, hm, vm, win);
  parallel_for(be, n * 3, [=] RRG_HD(int64_t i) {
    const T* s = vm + i * 5;
    T a, b, c;
    smap[i] = ssim_from_moments(s[0], s[1], s[2], s[3], s[4], win.c1, win.c2, &a, &b, &c);
    abc[i * 3 + 0] = a, abc[i * 3 + 1] = b, abc[i * 3 + 2] = c;
  });
  const T total = parallel_reduce(
      be, n * 3, T(0), [=] RRG_HD(int64_t i) { return smap[i]; }, [] RRG_HD(T a, T b) { return a + b; });
  if (!v_x.empty()) {
    ssim_window(be, w, h, 9, abc, hs, vs, win);
    const T scale = weight / T(n * 3);
    parallel_for(be, n * 3, [=] RRG_HD(int64_t i) {
      const T* s = vs + i * 3;
      v_x[i] += scale * (s[0] + T(2) * x[i] * s[1] + y[i] * s[2]);
    });
  }
  return total / T(n * 3);
}

// L_grad = ‖Sobel(C_r)‖₁ = mean over interior pixels (1 ≤ x ≤ W−2, 1 ≤ y ≤ H−2) and channels of
// |Gx| + |Gy|. Gradient gathered per pixel q from the 3×3 interior neighbours p:
// Σ_p sign(Gx(p)) kx(q − p) + sign(Gy(p)) ky(q − p).
// The Sobel term one element at a time (CUDA: one thread each); the CPU runs sobel_l1_loss_rows below.
template <class Backend, class T>
T sobel_l1_loss_elements(Backend be, int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs) {
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

// The same loss on the CPU, a row at a time: each row's responses and signs are computed with
// whole-row pointer arithmetic (no per-element index division), into `values` (the per-element
// |Gx| + |Gy|, 0 off the interior), whose sum is then reduced as sobel_l1_loss_elements reduces
// (the same chunks in the same order); the gradient gathers each row's nine offsets in the same
// (dy, dx) order. So both give the same floats (Losses.SobelRowsEqualThePerElementSums).
template <class T>
T sobel_l1_loss_rows(int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs, Span<T> values) {
  if (w < 3 || h < 3) return T(0);
  const T count = T(int64_t(w - 2) * (h - 2) * 3);
  const int64_t row = int64_t(w) * 3, n = row * h;
  if (values.size < n)
    throw std::invalid_argument("sobel_l1_loss_rows: " + std::to_string(values.size) + " values of working memory, " +
                                std::to_string(n) + " needed");
  const bool grad = !v_x.empty();
  const T* img = x.data;
  T* val = values.data;
  int8_t* sx = signs.data;  // here sign(Gx) of every element, then sign(Gy) (planar: vector loads)
  int8_t* sy = signs.data + (grad ? n : 0);
  parallel_for(CpuBackend{}, h, [=](int64_t y) {
    T* out = val + y * row;
    if (y < 1 || y > h - 2) {
      std::fill(out, out + row, T(0));
      return;
    }
    const T *up = img + (y - 1) * row, *mid = img + y * row, *dn = img + (y + 1) * row;
    const auto gx = [=](int64_t e) {  // as sobel_at, term by term
      return (up[e + 3] + T(2) * mid[e + 3] + dn[e + 3]) - (up[e - 3] + T(2) * mid[e - 3] + dn[e - 3]);
    };
    const auto gy = [=](int64_t e) { return (dn[e - 3] + T(2) * dn[e] + dn[e + 3]) - (up[e - 3] + T(2) * up[e] + up[e + 3]); };
    std::fill(out, out + 3, T(0));
    std::fill(out + row - 3, out + row, T(0));
    for (int64_t e = 3; e < row - 3; ++e) out[e] = abs_of(gx(e)) + abs_of(gy(e));
    if (!grad) return;
    // Local pointers: the byte stores could alias the closure's captures, which the compiler would
    // then reload every element. (a > 0) − (a < 0) is sign_of(a) (0 for NaN too), branch-free.
    int8_t* const ox = sx + y * row;
    int8_t* const oy = sy + y * row;
    for (int64_t e = 3; e < row - 3; ++e) {
      const T a = gx(e), b = gy(e);
      ox[e] = int8_t(int(a > T(0)) - int(a < T(0)));
      oy[e] = int8_t(int(b > T(0)) - int(b < T(0)));
    }
  });
  const T total = parallel_reduce(
      CpuBackend{}, n, T(0), [=](int64_t i) { return val[i]; }, [](T a, T b) { return a + b; });
  if (grad) {
    const T s = weight / count;
    T* v = v_x.data;
    parallel_for(CpuBackend{}, h, [=](int64_t qy) {
      T g[1024 * 3];  // a row's sums, in pieces of 1024 pixels
      for (int64_t e0 = 0; e0 < row; e0 += 1024 * 3) {
        const int64_t e1 = std::min(row, e0 + int64_t(1024) * 3);
        std::fill(g, g + (e1 - e0), T(0));
        for (int dy = -1; dy <= 1; ++dy) {
          const int64_t py = qy - dy;
          if (py < 1 || py > h - 2) continue;
          for (int dx = -1; dx <= 1; ++dx) {
            // p = q − (dx, dy) interior: 1 ≤ qx − dx ≤ w − 2
            const int64_t lo = std::max(e0, int64_t(1 + dx) * 3), hi = std::min(e1, int64_t(w - 1 + dx) * 3);
            const T kx = T(sobel_kx(dx, dy)), ky = T(sobel_ky(dx, dy));
            const int64_t p0 = py * row - int64_t(dx) * 3;  // element of p for element e of q: p0 + e
            const int8_t *px = sx + p0, *pyy = sy + p0;
            for (int64_t e = lo; e < hi; ++e) g[e - e0] += T(px[e]) * kx + T(pyy[e]) * ky;
          }
        }
        T* vq = v + qy * row;
        for (int64_t e = e0; e < e1; ++e) vq[e] += s * g[e - e0];
      }
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
T reflective_base_prior_cpu(Span<const T> C_b, Span<const T> R, Span<T> v_C, Span<T> v_C_r, T weight);
template <class T>
T ssim_cpu(int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight, SsimWindow<T> win,
           Span<T> scratch);
// values: w h 3 scalars of working memory (a buffer of its own is made when it is smaller).
template <class T>
T sobel_l1_loss_cpu(int w, int h, Span<const T> x, Span<T> v_x, T weight, Span<int8_t> signs, Span<T> values = {});

float l1_loss_cuda(Span<const float> x, Span<const float> y, Span<float> v_x, float weight);
float depth_l1_loss_cuda(Span<const float> d, Span<const float> d_gt, Span<float> v_d, float weight);
float reflective_base_prior_cuda(Span<const float> C_b, Span<const float> R, Span<float> v_C, Span<float> v_C_r,
                                 float weight);
float ssim_cuda(int w, int h, Span<const float> x, Span<const float> y, Span<float> v_x, float weight,
                SsimWindow<float> win, Span<float> scratch);
float sobel_l1_loss_cuda(int w, int h, Span<const float> x, Span<float> v_x, float weight, Span<int8_t> signs);

}  // namespace rrg::kernel
