#pragma once
// Per-pixel math of preprocess.h, shared by both back ends: the only copy.
#include "core/common/fast_math.h"
#include "core/common/hd.h"
#include "core/common/span.h"

#include <cmath>

namespace rrg::kernel {

// D'(u) = Σ_q w_s(q) w_d(q) D(q) / Σ_q w_s(q) w_d(q) over the valid q of the window,
// w_s = exp(-|u-q|² / 2σ_s²), w_d = exp(-(D(u)-D(q))² / 2σ_d²), taken together as one exponential
// (exp_neg: a polynomial on the host, which vectorises; expf on CUDA).
RRG_HD inline float bilateral_weight(int dx, int dy, float d, float c, float inv_2ss, float inv_2sd) {
  return exp_neg(-float(dx * dx + dy * dy) * inv_2ss - (d - c) * (d - c) * inv_2sd);
}

// The filtered depth from the sums over the window; 0 where the pixel has no depth.
RRG_HD inline float bilateral_result(float c, float sum, float wsum) {
  return c > 0.0f && wsum > 0.0f ? sum / wsum : 0.0f;
}

// One pixel, taps in row-major order (dy, then dx, ascending). The CPU runs the same taps in the
// same order over whole rows at once (preprocess_impl.h), adding the same terms to each pixel.
RRG_HD inline float bilateral_at(ImageView<const float> D, int x, int y, int radius, float inv_2ss,
                                 float inv_2sd) {
  const float c = D(x, y);
  if (!(c > 0.0f)) return 0.0f;
  float sum = 0.0f, wsum = 0.0f;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (!D.contains(qx, qy)) continue;
      const float d = D(qx, qy);
      if (!(d > 0.0f)) continue;
      const float w = bilateral_weight(dx, dy, d, c, inv_2ss, inv_2sd);
      sum += w * d;
      wsum += w;
    }
  return bilateral_result(c, sum, wsum);
}

// Output pixel (x, y) of the half-resolution level: mean of the valid pixels of the source block
// [2x, 2x+1] x [2y, 2y+1] that lie within 3σ_d of the block's first valid pixel.
RRG_HD inline float downsample_at(ImageView<const float> D, int x, int y, float max_diff) {
  float ref = 0.0f, sum = 0.0f;
  int n = 0;
  for (int k = 0; k < 4; ++k) {
    const int sx = 2 * x + (k & 1), sy = 2 * y + (k >> 1);
    if (!D.contains(sx, sy)) continue;
    const float d = D(sx, sy);
    if (!(d > 0.0f)) continue;
    if (n == 0) ref = d;
    if (fabsf(d - ref) > max_diff) continue;
    sum += d;
    ++n;
  }
  return n > 0 ? sum / float(n) : 0.0f;
}

}  // namespace rrg::kernel
