#pragma once
// Per-pixel math of preprocess.h, shared by both back ends: the only copy.
#include "core/common/hd.h"
#include "core/common/span.h"

#include <cmath>

namespace rrg::kernel {

// D'(u) = Σ_q w_s(q) w_d(q) D(q) / Σ_q w_s(q) w_d(q) over the valid q of the window,
// w_s = exp(-|u-q|² / 2σ_s²), w_d = exp(-(D(u)-D(q))² / 2σ_d²).
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
      const float w = expf(-float(dx * dx + dy * dy) * inv_2ss - (d - c) * (d - c) * inv_2sd);
      sum += w * d;
      wsum += w;
    }
  return wsum > 0.0f ? sum / wsum : 0.0f;
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
