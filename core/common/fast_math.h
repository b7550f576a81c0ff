#pragma once
// Scalar helpers for per-element code on both back ends, with the same results on both.
//
// Why they exist: the host build targets baseline x86-64 (SSE2), which has no rounding instruction,
// so floorf(x) becomes a long branchy sequence, and fminf / fmaxf are calls into libm (they must
// honour NaN operands). Ray marching and fusion run these per sample and per voxel. On CUDA each
// is one instruction already.
#include "core/common/hd.h"

#include <cmath>
#include <cstdint>
#include <cstring>

namespace rrg {

// floor(x) as an int, for |x| < 2^31 (voxel, block and pixel coordinates). Truncation rounds towards
// zero, so negative non-integers are one too high; the comparison takes that one back. Exact:
// every int of that range converts to float without rounding away a fraction that x has.
RRG_HD inline int floor_to_int(float x) {
#if defined(__CUDA_ARCH__)
  return __float2int_rd(x);
#else
  const int i = int(x);
  return i - int(x < float(i));
#endif
}

// Index of the lowest / highest set bit of x != 0 (tzcnt / lzcnt on the host, one instruction on CUDA).
RRG_HD inline int lowest_bit(uint32_t x) {
#if defined(__CUDA_ARCH__)
  return __ffs(int(x)) - 1;
#else
  return __builtin_ctz(x);
#endif
}
RRG_HD inline int highest_bit(uint32_t x) {
#if defined(__CUDA_ARCH__)
  return 31 - __clz(int(x));
#else
  return 31 - __builtin_clz(x);
#endif
}

// min / max of numbers that are never NaN (minss / maxss on the host).
RRG_HD inline float min_f(float a, float b) { return a < b ? a : b; }
RRG_HD inline float max_f(float a, float b) { return a > b ? a : b; }

// e^x on the host without libm, for per-element code that the compiler should vectorise: range
// reduction x = n ln2 + r, |r| <= ln2 / 2 (n rounded to nearest by the 1.5 * 2^23 shift; ln2 split in
// two so that n ln2 is exact), the degree-7 Taylor polynomial of e^r (truncation below r^8 / 8! e^r,
// about 1e-8 relative) and 2^n set in the exponent bits. x must lie in [-87, 88] (2^n stays a
// normal float). Plain arithmetic, inlined: the compiler evaluates eight of them at once in a
// vectorised loop with the same result as one at a time (no fused multiply-adds:
// cmake/cpu_arch.cmake), where a call to libm's expf keeps the loop scalar. Within 2 ulp of e^x
// (FastMath.ExpNegIsWithinTwoUlpOfExp, FastMath.ExpClampedIsWithinTwoUlpOfExp).
RRG_INLINE float exp_reduced_host(float x) {
  constexpr float kShift = 12582912.0f;      // 1.5 * 2^23
  constexpr uint32_t kShiftBits = 0x4B400000u;  // its bits
  const float t = x * 1.44269504f + kShift;
  const float n = t - kShift;  // round(x / ln2)
  const float r = (x - n * 0.693359375f) + n * 2.12194440e-4f;  // ln2 = 0.693359375 - 2.12194440e-4
  float p = 1.0f / 5040.0f;
  p = p * r + 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  // 2^n, n in [-126, 127]. Unsigned, so that x = NaN (which the clamps let through, and lanes whose
  // result is discarded do compute) wraps instead of overflowing a signed int; the result is NaN.
  uint32_t ti;
  std::memcpy(&ti, &t, sizeof ti);
  const uint32_t bits = (ti - kShiftBits + 127u) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

// e^x for x <= 0 (Gaussian weights: the splat falloff, the bilateral filter); x is clamped to
// [-87, 0], which keeps the result a normal float (e^-87 = 1.6e-38 stands for anything smaller).
// CUDA: expf; host: exp_reduced_host.
RRG_HD RRG_INLINE float exp_neg(float x) {
#if defined(__CUDA_ARCH__)
  return expf(x);
#else
  return exp_reduced_host(x < -87.0f ? -87.0f : (x > 0.0f ? 0.0f : x));
#endif
}

// e^x with x clamped to [-87, 88] (e^88 = 1.7e38 stands for anything larger): the projection's
// scales exp(log s) and opacities sigmoid(l). CUDA: expf (inf above 88.7, a denormal or 0 below
// -87); host: exp_reduced_host.
RRG_HD RRG_INLINE float exp_clamped(float x) {
#if defined(__CUDA_ARCH__)
  return expf(x);
#else
  return exp_reduced_host(x < -87.0f ? -87.0f : (x > 88.0f ? 88.0f : x));
#endif
}

}  // namespace rrg
