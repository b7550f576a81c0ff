#pragma once
// The bodies of preprocess.h, templated on the back-end tag; instantiated by preprocess_cpu.cpp
// and preprocess_cuda.cu.
#include "core/tracking/preprocess_device.h"

namespace rrg::kernel {

template <class Backend>
void bilateral(Backend backend, ImageView<const float> in, ImageView<float> out, int radius, float sigma_s,
               float sigma_d) {
  const float inv_2ss = 0.5f / (sigma_s * sigma_s), inv_2sd = 0.5f / (sigma_d * sigma_d);
  const int w = in.width;
  parallel_for(backend, in.size(), [=] RRG_HD(int64_t i) {
    out[i] = bilateral_at(in, int(i % w), int(i / w), radius, inv_2ss, inv_2sd);
  });
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
