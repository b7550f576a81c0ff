#pragma once
// Scalar helpers for per-element code on both back ends, with the same results on both.
//
// Why they exist: the host build targets baseline x86-64 (SSE2), which has no rounding instruction,
// so floorf(x) becomes a long branchy sequence, and fminf / fmaxf are calls into libm (they must
// honour NaN operands). Ray marching and fusion run these per sample and per voxel. On CUDA each
// is one instruction already.
#include "core/common/hd.h"

#include <cmath>

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

// min / max of numbers that are never NaN (minss / maxss on the host).
RRG_HD inline float min_f(float a, float b) { return a < b ? a : b; }
RRG_HD inline float max_f(float a, float b) { return a > b ? a : b; }

}  // namespace rrg
