#pragma once
// Per-pixel math of the mapping losses (paper §4.2.2), shared by both back ends: the only copy.
// Templated on the scalar so the tests can run the same code in double for finite differences.
#include "core/common/hd.h"

#include <cmath>

namespace rrg::kernel {

inline constexpr int kSsimRadius = 5;  // 11 x 11 window (3DGS)

// The normalised 1-D Gaussian window g[k] ∝ exp(-(k - 5)² / (2 · 1.5²)), passed to kernels by value.
template <class T>
struct SsimWindow {
  T g[2 * kSsimRadius + 1];
  T c1, c2;  // (0.01)², (0.03)²
};

template <class T>
RRG_HD inline T sign_of(T x) {
  return x > T(0) ? T(1) : (x < T(0) ? T(-1) : T(0));
}

template <class T>
RRG_HD inline T abs_of(T x) {
  return x < T(0) ? -x : x;
}

// SSIM(p) = (2 μx μy + C1)(2 σxy + C2) / ((μx² + μy² + C1)(σxx + σyy + C2)) from the windowed raw
// moments E[x], E[y], E[x²], E[y²], E[xy]; also its partials a = ∂S/∂E[x], b = ∂S/∂E[x²],
// c = ∂S/∂E[xy] (the moments of the reference image y are constants).
template <class T>
RRG_HD inline T ssim_from_moments(T mx, T my, T exx, T eyy, T exy, T c1, T c2, T* a, T* b, T* c) {
  const T sxx = exx - mx * mx, syy = eyy - my * my, sxy = exy - mx * my;
  const T A1 = T(2) * mx * my + c1, A2 = T(2) * sxy + c2;
  const T B1 = mx * mx + my * my + c1, B2 = sxx + syy + c2;
  const T S = (A1 * A2) / (B1 * B2);
  // dS = S (dA1/A1 + dA2/A2 - dB1/B1 - dB2/B2); dA1/dmx = 2my, dA2/dmx = -2my, dB1/dmx = 2mx,
  // dB2/dmx = -2mx; dB2/dexx = 1; dA2/dexy = 2.
  *a = S * (T(2) * my / A1 - T(2) * my / A2 - T(2) * mx / B1 + T(2) * mx / B2);
  *b = -S / B2;
  *c = T(2) * S / A2;
  return S;
}

// Sobel responses at interior pixel (x, y) of channel ch of an interleaved RGB image:
// Gx = [-1 0 1; -2 0 2; -1 0 1] ⋆ I, Gy = Gxᵀ ⋆ I.
template <class T>
RRG_HD inline void sobel_at(const T* img, int w, int x, int y, int ch, T* gx, T* gy) {
  auto at = [&](int xx, int yy) { return img[(int64_t(yy) * w + xx) * 3 + ch]; };
  *gx = (at(x + 1, y - 1) + T(2) * at(x + 1, y) + at(x + 1, y + 1)) -
        (at(x - 1, y - 1) + T(2) * at(x - 1, y) + at(x - 1, y + 1));
  *gy = (at(x - 1, y + 1) + T(2) * at(x, y + 1) + at(x + 1, y + 1)) -
        (at(x - 1, y - 1) + T(2) * at(x, y - 1) + at(x + 1, y - 1));
}

// Sobel kernel weights kx(dx, dy), ky(dx, dy) for the offset (dx, dy) in [-1, 1]².
RRG_HD inline int sobel_kx(int dx, int dy) { return dx * (dy == 0 ? 2 : 1); }
RRG_HD inline int sobel_ky(int dx, int dy) { return dy * (dx == 0 ? 2 : 1); }

}  // namespace rrg::kernel
