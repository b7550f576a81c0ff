#pragma once
// SSIM on the CPU streamed over rows: ssim() (losses_impl.h) with its intermediate images kept to a
// few rows. The separable passes run as there (the moments' horizontal sums, their vertical sums,
// the SSIM map with a, b, c, their horizontal then vertical sums, the gradient), each element's
// taps in the same order, so the floats are the same (Losses.SsimRowsEqualTheSeparatePasses); but
// each band of rows keeps the 11 rows of horizontal sums its vertical sums need in a ring instead
// of whole images (75 scalars per pixel at 320x240 is 23 MB of traffic per pass), and recomputes
// the 2R + R rows of halo its neighbours also compute. The SSIM map alone is kept whole, and
// reduced as ssim() reduces it.
#include "core/common/span.h"
#include "core/gaussians/losses_device.h"

namespace rrg::kernel {

// Scalars of scratch the streamed SSIM needs for a w x h image split into `bands` bands.
int64_t ssim_rows_scratch(int w, int h, int bands);
// Bands the CPU's threads use for a w x h image.
int ssim_rows_bands(int h);

// As ssim(CpuBackend, ...): returns SSIM, adds weight · ∂SSIM/∂x to v_x when it is not empty.
// scratch: at least ssim_rows_scratch(w, h, ssim_rows_bands(h)) scalars (kSsimScratch · w · h is).
template <class T>
T ssim_rows(int w, int h, Span<const T> x, Span<const T> y, Span<T> v_x, T weight, const SsimWindow<T>& win,
            Span<T> scratch);

}  // namespace rrg::kernel
