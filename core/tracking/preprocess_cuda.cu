#include "core/common/parallel_for_cuda.cuh"
#include "core/tracking/preprocess_impl.h"

namespace rrg::kernel {

void bilateral_cuda(ImageView<const float> in, ImageView<float> out, int radius, float sigma_s, float sigma_d) {
  bilateral(CudaBackend{}, in, out, radius, sigma_s, sigma_d);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}
void downsample_cuda(ImageView<const float> in, ImageView<float> out, float max_diff) {
  downsample(CudaBackend{}, in, out, max_diff);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
