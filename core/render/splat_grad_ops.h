#pragma once
// Per-Gaussian splat-gradient helpers shared by the backward rasterisers of both back ends.
#include "core/common/atomics.h"
#include "core/render/splat.h"

namespace rrg::kernel {

// True when every field is zero (the splat did not touch the pixel).
RRG_HD inline bool is_zero(const SplatGrad& g) {
  const float* s = &g.mean[0];
  for (int k = 0; k < int(sizeof(SplatGrad) / sizeof(float)); ++k)
    if (s[k] != 0.0f) return false;
  return true;
}

// True when every channel of an upstream gradient is exactly zero (a pixel with nothing to send
// back). Not Eigen's isZero(): that tests |x| <= 1e-5 for float, and an upstream of a mean loss is
// weight / (3 · pixels) per channel, 1.4e-6 for the L1 term at 512x384, so pixels with a real
// gradient were skipped (more of them the larger the image).
RRG_HD inline bool exactly_zero(const Vec3<float>& v) { return v[0] == 0.0f && v[1] == 0.0f && v[2] == 0.0f; }

// One atomic add per non-zero field into the shared splat gradient.
RRG_HD inline void atomic_add_grad(SplatGrad* dst, const SplatGrad& g) {
  float* d = &dst->mean[0];
  const float* s = &g.mean[0];
  for (int k = 0; k < int(sizeof(SplatGrad) / sizeof(float)); ++k)
    if (s[k] != 0.0f) atomic_add(d + k, s[k]);
}

}  // namespace rrg::kernel
