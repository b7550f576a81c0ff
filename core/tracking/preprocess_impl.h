#pragma once
// The bodies of preprocess.h, templated on the back-end tag; instantiated by preprocess_cpu.cpp
// and preprocess_cuda.cu.
#include "core/common/parallel_for.h"
#include "core/tracking/preprocess_device.h"

#include <algorithm>
#include <type_traits>
#include <vector>

namespace rrg::kernel {

template <class Backend>
void bilateral(Backend backend, ImageView<const float> in, ImageView<float> out, int radius, float sigma_s,
               float sigma_d) {
  const float inv_2ss = 0.5f / (sigma_s * sigma_s), inv_2sd = 0.5f / (sigma_d * sigma_d);
  const int w = in.width, h = in.height;
  if constexpr (std::is_same_v<Backend, CpuBackend>) {
    // A row at a time, tap by tap: for each (dy, dx) the pixels whose neighbour is inside the
    // image form one run, and the loop over it is vector code (exp_neg inlined). Each pixel gets
    // bilateral_at's terms in bilateral_at's order: the same result.
    parallel_for(backend, h, [=](int64_t row) {
      const int y = int(row);
      const float* c = &in(0, y);
      std::vector<float> sum(size_t(w), 0.0f), wsum(size_t(w), 0.0f);
      for (int dy = -radius; dy <= radius; ++dy) {
        if (y + dy < 0 || y + dy >= h) continue;
        for (int dx = -radius; dx <= radius; ++dx) {
          const float* q = &in(0, y + dy);  // q[x + dx] = D(x + dx, y + dy)
          const int x0 = std::max(0, -dx), x1 = std::min(w, w - dx);
          float* __restrict s = sum.data();
          float* __restrict ws = wsum.data();
#pragma omp simd
          for (int x = x0; x < x1; ++x) {
            const float d = q[x + dx];
            const float wt = bilateral_weight(dx, dy, d, c[x], inv_2ss, inv_2sd);
            const bool valid = d > 0.0f;
            s[x] += valid ? wt * d : 0.0f;
            ws[x] += valid ? wt : 0.0f;
          }
        }
      }
      float* o = &out(0, y);
      for (int x = 0; x < w; ++x) o[x] = bilateral_result(c[x], sum[size_t(x)], wsum[size_t(x)]);
    });
  } else {
    parallel_for(backend, in.size(), [=] RRG_HD(int64_t i) {
      out[i] = bilateral_at(in, int(i % w), int(i / w), radius, inv_2ss, inv_2sd);
    });
  }
}

template <class Backend>
void downsample(Backend backend, ImageView<const float> in, ImageView<float> out, float max_diff) {
  const int w = out.width;
  parallel_for(backend, out.size(), [=] RRG_HD(int64_t i) {
    out[i] = downsample_at(in, int(i % w), int(i / w), max_diff);
  });
}

void bilateral_cpu(ImageView<const float> in, ImageView<float> out, int radius, float sigma_s, float sigma_d);
void downsample_cpu(ImageView<const float> in, ImageView<float> out, float max_diff);
void bilateral_cuda(ImageView<const float> in, ImageView<float> out, int radius, float sigma_s, float sigma_d);
void downsample_cuda(ImageView<const float> in, ImageView<float> out, float max_diff);

}  // namespace rrg::kernel
