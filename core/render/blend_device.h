#pragma once
// One splat at one pixel, for pass 2 (base, sort-free weighted sum with the depth cull) and pass 3
// (reflection, front-to-back alpha compositing with the plane test): forward and backward, the only
// copy of the math. Used by the CPU loop and by the CUDA kernels alike.
#include "core/common/fast_math.h"
#include "core/render/splat.h"

namespace rrg::kernel {

inline constexpr float kAlphaMin = 1.0f / 255.0f;    // smaller alphas are skipped (3DGS)
inline constexpr float kAlphaMax = 0.99f;            // pass-3 alphas are clamped here (3DGS)
inline constexpr float kTransmittanceMin = 1e-4f;    // pass 3 stops before T drops below this
// Exponents below ln(kAlphaMin) - 1e-3 give alpha < kAlphaMin for any opacity <= 1: rejected
// before the exp (an exact shortcut, not a new threshold).
inline constexpr float kPowerMin = -5.5422645f;

// e^x for the falloff, x = power in [kPowerMin, 0]: exp_neg (core/common/fast_math.h), a polynomial
// on the host that the CPU rasteriser's lane loop evaluates on eight pixels at once; expf on CUDA.
RRG_HD RRG_INLINE float falloff_exp(float x) { return exp_neg(x); }
RRG_HD RRG_INLINE double falloff_exp(double x) { return k_exp(x); }

// The falloff of splat s at pixel (px, py): offset d = p_hat - u and G = exp(power), with
// power = -1/2 d^T Sigma'^-1 d. valid is false when the exponent is positive (as in 3DGS) or below
// kPowerMin (alpha < kAlphaMin for any opacity <= 1); G is not computed then.
template <class T>
struct SplatFalloffT {
  T dx, dy, G;
  bool valid;
};

// The pieces, on scalars (the CPU forward of pass 2 evaluates them on eight pixels at once):
// power = -1/2 d^T Sigma'^-1 d at offset d = (dx, dy); whether it gives a falloff; G = exp(power)
// where it does, else 0; alpha from G.
template <class T>
RRG_HD inline T splat_power(const SplatT<T>& s, T dx, T dy) {
  return T(-0.5) * (s.conic[0] * dx * dx + s.conic[2] * dy * dy) - s.conic[1] * dx * dy;
}

template <class T>
RRG_HD inline bool power_valid(T power) {
  return !((power > T(0)) | (power < T(kPowerMin)));
}

template <class T>
RRG_HD inline T power_falloff(T power) {
  return power_valid(power) ? falloff_exp(power) : T(0);
}

// alpha_i(u) = min(sigma_i G, alpha_max), or 0 below kAlphaMin, for a valid falloff G.
template <class T>
RRG_HD inline T falloff_alpha(T opacity, T G, T alpha_max) {
  T alpha = opacity * G;
  alpha = alpha > alpha_max ? alpha_max : alpha;
  return alpha < T(kAlphaMin) ? T(0) : alpha;
}

template <class T>
RRG_HD inline SplatFalloffT<T> splat_falloff(const SplatT<T>& s, T px, T py) {
  SplatFalloffT<T> f;
  f.dx = s.mean[0] - px;
  f.dy = s.mean[1] - py;
  const T power = splat_power(s, f.dx, f.dy);
  f.valid = power_valid(power);
  f.G = power_falloff(power);
  return f;
}

// alpha_i(u) = min(sigma_i G, alpha_max), or 0 when below kAlphaMin or the falloff is not valid.
template <class T>
RRG_HD inline T splat_alpha(const SplatT<T>& s, const SplatFalloffT<T>& f, T alpha_max) {
  return f.valid ? falloff_alpha(s.opacity, f.G, alpha_max) : T(0);
}

template <class T>
RRG_HD inline T splat_alpha(const SplatT<T>& s, T px, T py, T alpha_max) {
  return splat_alpha(s, splat_falloff(s, px, py), alpha_max);
}

// The pixels where splat_alpha can be non-zero, as a rectangle [x0, x1] x [y0, y1] (inclusive,
// pixel centres at integer coordinates); false when there are none (opacity below kAlphaMin).
// alpha >= kAlphaMin needs q = d^T Sigma'^-1 d <= kappa = 2 ln(opacity / kAlphaMin), an ellipse
// whose half-extents are sqrt(kappa (Sigma')_xx) and sqrt(kappa (Sigma')_yy), with Sigma' the
// inverse of the conic. kappa is widened by 1e-3 relative so that float rounding of the per-pixel
// test never admits a pixel outside. A conic that is not positive definite gives an unbounded rect.
template <class T>
RRG_HD inline bool splat_pixel_bounds(const SplatT<T>& s, int& x0, int& y0, int& x1, int& y1) {
  if (s.opacity < T(kAlphaMin)) return false;  // (NaN goes on to the unbounded case below)
  const T a = s.conic[0], b = s.conic[1], c = s.conic[2], det = a * c - b * b;
  constexpr int kUnbounded = 1 << 28;
  if (!(det > T(0)) || !(a > T(0))) {
    x0 = y0 = -kUnbounded;
    x1 = y1 = kUnbounded;
    return true;
  }
  const T kappa = T(2.002) * k_log(s.opacity / T(kAlphaMin)) + T(1e-6);
  const T ex = k_sqrt(kappa * c / det), ey = k_sqrt(kappa * a / det);
  if (!(ex < T(kUnbounded) && ey < T(kUnbounded) && s.mean[0] == s.mean[0] && s.mean[1] == s.mean[1])) {
    x0 = y0 = -kUnbounded;  // NaN or huge: let the per-pixel test decide everywhere
    x1 = y1 = kUnbounded;
    return true;
  }
  auto to_int = [](T v) { return v < T(-kUnbounded) ? -kUnbounded : (v > T(kUnbounded) ? kUnbounded : int(v)); };
  x0 = to_int(k_ceil(s.mean[0] - ex));
  x1 = to_int(k_floor(s.mean[0] + ex));
  y0 = to_int(k_ceil(s.mean[1] - ey));
  y1 = to_int(k_floor(s.mean[1] + ey));
  return x0 <= x1 && y0 <= y1;
}

// v += d alpha / d(splat) * v_alpha, for an alpha splat_alpha returned non-zero from falloff f.
template <class T>
RRG_HD inline void splat_alpha_bwd(const SplatT<T>& s, const SplatFalloffT<T>& f, T alpha_max, T v_alpha, SplatT<T>& v) {
  const T dx = f.dx, dy = f.dy, G = f.G;
  if (s.opacity * G > alpha_max) return;  // clamped: constant
  v.opacity += G * v_alpha;
  const T v_power = s.opacity * G * v_alpha;
  v.conic[0] += T(-0.5) * dx * dx * v_power;
  v.conic[1] += -dx * dy * v_power;
  v.conic[2] += T(-0.5) * dy * dy * v_power;
  v.mean[0] += -(s.conic[0] * dx + s.conic[1] * dy) * v_power;
  v.mean[1] += -(s.conic[1] * dx + s.conic[2] * dy) * v_power;
}

// ---- pass 2: A_b[x](u) = sum_i 1(d_i < D_t(u) + eps) alpha_i(u) x_i --------------------------

template <class T>
struct BaseAccumT {
  Vec3<T> C_g = Vec3<T>::Zero();  // A_b[c]
  T W_g = T(0);                   // A_b[1]
  T D_g = T(0);                   // A_b[d]
};

// The depth cull. Where the raycast missed (D_t = 0) there is no surface to cull against.
template <class T>
RRG_HD inline bool base_visible(const SplatT<T>& s, T D_t, T eps) {
  const T d = s.depth;
  return !(D_t > T(0)) | (d < D_t + eps);
}

// Adds splat s with its (non-zero) alpha at a pixel, field by field (the CPU lane loop keeps each
// field of a tile in its own array).
template <class T>
RRG_HD inline void base_add(T& C0, T& C1, T& C2, T& W_g, T& D_g, const SplatT<T>& s, T alpha) {
  C0 += alpha * s.color[0];
  C1 += alpha * s.color[1];
  C2 += alpha * s.color[2];
  W_g += alpha;
  D_g += alpha * s.depth;
}

template <class T>
RRG_HD inline void base_add(BaseAccumT<T>& acc, const SplatT<T>& s, T alpha) {
  base_add(acc.C_g[0], acc.C_g[1], acc.C_g[2], acc.W_g, acc.D_g, s, alpha);
}

// Pass 2's falloff G of splat s at offset (dx, dy) from a pixel whose raycast depth is D_t: 0 where
// it adds nothing (depth cull, outside its ellipse); its alpha is then falloff_alpha(opacity, G, 1)
// where G != 0 (G > exp(kPowerMin) there), else 0.
// (Both evaluate every term and then select, with no short-circuit and no memory read under a
// condition: the form GCC turns into straight vector code in the CPU lane loop.)
template <class T>
RRG_HD inline T base_falloff_G(const SplatT<T>& s, T dx, T dy, T D_t, T eps) {
  const T G = power_falloff(splat_power(s, dx, dy));
  return base_visible(s, D_t, eps) ? G : T(0);
}

template <class T>
RRG_HD inline T base_alpha(const SplatT<T>& s, T G) {
  const T alpha = falloff_alpha(s.opacity, G, T(1));
  return G != T(0) ? alpha : T(0);
}

// The falloff of splat s at pixel (px, py) where it adds to pass 2, and its alpha; alpha = 0 when
// it adds nothing there (depth cull, outside its ellipse, alpha below kAlphaMin).
template <class T>
RRG_HD inline T base_falloff(const SplatT<T>& s, T px, T py, T D_t, T eps, SplatFalloffT<T>& f) {
  f.dx = s.mean[0] - px;
  f.dy = s.mean[1] - py;
  f.G = base_falloff_G(s, f.dx, f.dy, D_t, eps);
  f.valid = f.G != T(0);
  return base_alpha(s, f.G);
}

// Adds splat s at pixel (px, py); returns its alpha (0 when culled or negligible).
template <class T>
RRG_HD inline T base_accumulate(BaseAccumT<T>& acc, const SplatT<T>& s, T px, T py, T D_t, T eps) {
  SplatFalloffT<T> f{};
  const T alpha = base_falloff(s, px, py, D_t, eps, f);
  if (alpha != T(0)) base_add(acc, s, alpha);
  return alpha;
}

// Denominator of the base composite: 1 + W_g on a raycast hit; max(1, W_g) on a miss, where the
// TSDF term has no weight (C_t = 0, D_t = 0) and the Gaussians alone give C_b and D_b.
template <class T>
RRG_HD inline T base_denominator(T W_g, T D_t) {
  if (D_t > T(0)) return T(1) + W_g;
  return W_g > T(1) ? W_g : T(1);
}

// C_b = (C_t + C_g) / (1 + W_g), D_b = (D_t + D_g) / (1 + W_g) (misses: see base_denominator).
template <class T>
RRG_HD inline void base_resolve(const BaseAccumT<T>& acc, const Vec3<T>& C_t, T D_t, Vec3<T>& C_b, T& D_b) {
  const T den = base_denominator(acc.W_g, D_t);
  const bool hit = D_t > T(0);
  C_b = ((hit ? C_t : Vec3<T>::Zero()) + acc.C_g) / den;
  D_b = ((hit ? D_t : T(0)) + acc.D_g) / den;
}

// Upstream gradients of the accumulators from v_C_b, v_D_b.
template <class T>
struct BaseUpstreamT {
  Vec3<T> v_C_g;
  T v_W_g, v_D_g;
};

template <class T>
RRG_HD inline BaseUpstreamT<T> base_resolve_bwd(T W_g, T D_t, const Vec3<T>& C_b, T D_b, const Vec3<T>& v_C_b,
                                                T v_D_b) {
  const T den = base_denominator(W_g, D_t);
  BaseUpstreamT<T> u;
  u.v_C_g = v_C_b / den;
  u.v_D_g = v_D_b / den;
  const bool den_varies = D_t > T(0) || W_g > T(1);
  u.v_W_g = den_varies ? -(v_C_b.dot(C_b) + v_D_b * D_b) / den : T(0);
  return u;
}

// Gradient into v of splat s's contribution alpha (non-zero) with falloff f at a pixel.
template <class T>
RRG_HD inline void base_splat_bwd(const SplatT<T>& s, const SplatFalloffT<T>& f, T alpha, const BaseUpstreamT<T>& u,
                                  SplatT<T>& v) {
  const Vec3<T> c(s.color[0], s.color[1], s.color[2]);
  const T v_alpha = u.v_C_g.dot(c) + u.v_W_g + u.v_D_g * s.depth;
  for (int ch = 0; ch < 3; ++ch) v.color[ch] += alpha * u.v_C_g[ch];
  v.depth += alpha * u.v_D_g;
  splat_alpha_bwd(s, f, T(1), v_alpha, v);
}

// Gradient of splat s's contribution at (px, py) into v.
template <class T>
RRG_HD inline void base_splat_bwd(const SplatT<T>& s, T px, T py, T D_t, T eps, const BaseUpstreamT<T>& u,
                                  SplatT<T>& v) {
  SplatFalloffT<T> f{};
  const T alpha = base_falloff(s, px, py, D_t, eps, f);
  if (alpha != T(0)) base_splat_bwd(s, f, alpha, u, v);
}

// ---- pass 3: A_r[x](u) = sum_i prod_{j<i} (1 - alpha_j) alpha_i x_i, alpha with 1(l_i == I(u)) ------

template <class T>
struct ReflStateT {
  T trans = T(1);                 // T: transmittance so far
  Vec3<T> C = Vec3<T>::Zero();    // C_r so far (in the backward pass: the prefix P_i)
  T W = T(0);                     // W_r so far
};

// Composites splat s (already known to pass the plane test) behind the current state. Returns false
// when the pixel is saturated (T would drop below kTransmittanceMin; s is then not added).
template <class T>
RRG_HD inline bool refl_step(ReflStateT<T>& st, const SplatT<T>& s, T px, T py) {
  const T alpha = splat_alpha(s, px, py, T(kAlphaMax));
  if (alpha == T(0)) return true;
  const T next = st.trans * (T(1) - alpha);
  if (next < T(kTransmittanceMin)) return false;
  const T w = alpha * st.trans;
  st.C += w * Vec3<T>(s.color[0], s.color[1], s.color[2]);
  st.W += w;
  st.trans = next;
  return true;
}

// Whether the mean RGB of C_r so far is above `stop`. C_r only grows along a pixel's list (weights
// alpha T >= 0, colours max(SH + 0.5, 0) >= 0, per channel), so once it is above it stays above: a
// caller that needs only that test (the tracking mask, mask_source.h: the same sum / 3 > threshold)
// may stop compositing the pixel there. +inf never stops.
template <class T>
RRG_HD inline bool refl_mean_above(const ReflStateT<T>& st, T stop) {
  return st.C.sum() / T(3) > stop;
}

// Backward of refl_step, replayed front to back with the final C_r, W_r of the pixel:
// dC/dalpha_i = T_i c_i - (C - P_i) / (1 - alpha_i), P_i the colour up to and including i.
template <class T>
RRG_HD inline bool refl_step_bwd(ReflStateT<T>& st, const SplatT<T>& s, T px, T py, const Vec3<T>& C_final,
                                 T W_final, const Vec3<T>& v_C, T v_W, SplatT<T>& v) {
  const SplatFalloffT<T> f = splat_falloff(s, px, py);
  const T alpha = splat_alpha(s, f, T(kAlphaMax));
  if (alpha == T(0)) return true;
  const T next = st.trans * (T(1) - alpha);
  if (next < T(kTransmittanceMin)) return false;
  const Vec3<T> c(s.color[0], s.color[1], s.color[2]);
  const T w = alpha * st.trans;
  st.C += w * c;
  st.W += w;
  const T inv = T(1) / (T(1) - alpha);
  const T v_alpha = v_C.dot(st.trans * c - (C_final - st.C) * inv) + v_W * (st.trans - (W_final - st.W) * inv);
  for (int ch = 0; ch < 3; ++ch) v.color[ch] += w * v_C[ch];
  splat_alpha_bwd(s, f, T(kAlphaMax), v_alpha, v);
  st.trans = next;
  return true;
}

// ---- pixels in tile-major order: a warp / a thread's chunk stays inside one tile -------------------

// Slot i -> pixel (x, y) and its tile; false for slots past the image edge.
RRG_HD inline bool tile_pixel(int64_t i, int width, int height, int tiles_x, int& x, int& y, int& tile) {
  constexpr int kTilePixels = kTileSize * kTileSize;
  tile = int(i / kTilePixels);
  const int local = int(i % kTilePixels);
  x = (tile % tiles_x) * kTileSize + local % kTileSize;
  y = (tile / tiles_x) * kTileSize + local / kTileSize;
  return x < width && y < height;
}

}  // namespace rrg::kernel
