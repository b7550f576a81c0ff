#include "core/gaussians/ssim_rows_cpu.h"

#include "core/common/parallel_for.h"
#include "core/gaussians/losses_impl.h"

#include <omp.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rrg::kernel {

namespace {

constexpr int R = kSsimRadius;
constexpr int kRing = 2 * R + 1;
constexpr int kMom = 15;  // per pixel: 3 channels x (x, y, x², y², xy)
constexpr int kAbc = 9;   // per pixel: 3 channels x (a, b, c)

// Per band: the ring of horizontal moment sums, one moment row, one vertical row; the ring of
// horizontal a, b, c sums, one a, b, c row, one vertical row.
int64_t band_scalars(int w) { return int64_t(w) * (kRing * kMom + 2 * kMom + kRing * kAbc + 2 * kAbc); }

// out = Σ_k g[k + R] · rows(y + k) over the rows inside the image, in ascending k, from 0: the
// vertical ssim_pass_row over a ring of rows.
template <class T>
void vertical(T* const* ring, T* out, int64_t len, int h, int y, const SsimWindow<T>& win) {
  std::fill(out, out + len, T(0));
  for (int k = -R; k <= R; ++k) {
    if (y + k < 0 || y + k >= h) continue;
    const T g = win.g[k + R];
    const T* s = ring[(y + k + kRing) % kRing];
    for (int64_t e = 0; e < len; ++e) out[e] += g * s[e];
  }
}

}  // namespace

int64_t ssim_rows_scratch(int w, int h, int bands) { return int64_t(w) * h * 3 + bands * band_scalars(w); }

int ssim_rows_bands(int h) { return std::max(1, std::min(omp_get_max_threads(), h / 32)); }

template <class T>
T ssim_rows(int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight, const SsimWindow<T>& win,
            Span<T> scratch) {
  const int bands = ssim_rows_bands(h);
  const int64_t n = int64_t(w) * h;
  if (scratch.size < ssim_rows_scratch(w, h, bands))
    throw std::invalid_argument("ssim: the scratch holds " + std::to_string(scratch.size) + " scalars, " +
                                std::to_string(ssim_rows_scratch(w, h, bands)) + " needed");
  T* smap = scratch.data;  // [N, 3], reduced below as ssim() reduces it
  const bool grad = !v_x.empty();
  const int64_t mrow = int64_t(w) * kMom, arow = int64_t(w) * kAbc;
#pragma omp parallel for schedule(static, 1)
  for (int band = 0; band < bands; ++band) {
    const int r0 = int(int64_t(h) * band / bands), r1 = int(int64_t(h) * (band + 1) / bands);
    T* base = scratch.data + n * 3 + band * band_scalars(w);
    T* hm[kRing];
    for (int i = 0; i < kRing; ++i) hm[i] = base + i * mrow;
    T* mom = base + kRing * mrow;
    T* vm = mom + mrow;
    T* hs[kRing];
    for (int i = 0; i < kRing; ++i) hs[i] = vm + mrow + i * arow;
    T* abc = vm + mrow + kRing * arow;
    T* vs = abc + arow;
    // Rows the band's output needs: gradient rows [r0, r1) read a, b, c rows ± R, which read
    // moment rows ± R more (without the gradient, the map's rows [r0, r1) only).
    const int b_lo = grad ? std::max(0, r0 - R) : r0, b_hi = grad ? std::min(h, r1 + R) : r1;
    int next_h = std::max(0, b_lo - R);  // next row of horizontal moment sums
    int next_b = b_lo;                   // next row of the map (and a, b, c)
    const auto moments_row = [&](int r) {  // as ssim()'s moments, then its horizontal pass
      for (int64_t i = 0; i < int64_t(w) * 3; ++i) {
        const T a = x[int64_t(r) * w * 3 + i], b = y[int64_t(r) * w * 3 + i];
        T* m = mom + i * 5;
        m[0] = a, m[1] = b, m[2] = a * a, m[3] = b * b, m[4] = a * b;
      }
      ssim_pass_row(mom, hm[r % kRing], w, 1, kMom, false, 0, win);
    };
    const auto map_row = [&](int r) {  // the map, and a, b, c with their horizontal sums
      while (next_h <= std::min(h - 1, r + R)) moments_row(next_h++);
      vertical(hm, vm, mrow, h, r, win);
      const bool own = r >= r0 && r < r1;
      for (int64_t i = 0; i < int64_t(w) * 3; ++i) {
        const T* s = vm + i * 5;
        T a, b, c;
        const T v = ssim_from_moments(s[0], s[1], s[2], s[3], s[4], win.c1, win.c2, &a, &b, &c);
        if (own) smap[int64_t(r) * w * 3 + i] = v;
        abc[i * 3 + 0] = a, abc[i * 3 + 1] = b, abc[i * 3 + 2] = c;
      }
      if (grad) ssim_pass_row(abc, hs[r % kRing], w, 1, kAbc, false, 0, win);
    };
    if (!grad) {
      for (int r = r0; r < r1; ++r) map_row(r);
      continue;
    }
    const T scale = weight / T(n * 3);
    for (int r = r0; r < r1; ++r) {
      while (next_b <= std::min(b_hi - 1, r + R)) map_row(next_b++);
      vertical(hs, vs, arow, h, r, win);
      for (int64_t i = 0; i < int64_t(w) * 3; ++i) {
        const int64_t j = int64_t(r) * w * 3 + i;
        const T* s = vs + i * 3;
        v_x[j] += scale * (s[0] + T(2) * x[j] * s[1] + y[j] * s[2]);
      }
    }
  }
  const T total = parallel_reduce(
      CpuBackend{}, n * 3, T(0), [=](int64_t i) { return smap[i]; }, [](T a, T b) { return a + b; });
  return total / T(n * 3);
}

template float ssim_rows<float>(int, int, Span<const float>, Span<const float>, Span<float>, float,
                                const SsimWindow<float>&, Span<float>);
template double ssim_rows<double>(int, int, Span<const double>, Span<const double>, Span<double>, double,
                                  const SsimWindow<double>&, Span<double>);

}  // namespace rrg::kernel
