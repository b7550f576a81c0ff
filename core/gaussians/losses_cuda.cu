#include "core/common/parallel_for_cuda.cuh"
#include "core/gaussians/losses_impl.h"

namespace rrg::kernel {

// parallel_reduce synchronises; the gradient-only launches are synchronised here.
float l1_loss_cuda(Span<const float> x, Span<const float> y, Span<float> v_x, float weight) {
  const float r = l1_loss(CudaBackend{}, x, y, v_x, weight);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
  return r;
}
float depth_l1_loss_cuda(Span<const float> d, Span<const float> d_gt, Span<float> v_d, float weight) {
  const float r = depth_l1_loss(CudaBackend{}, d, d_gt, v_d, weight);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
  return r;
}
float reflective_base_prior_cuda(Span<const float> C_b, Span<const float> R, Span<float> v_C, Span<float> v_C_r,
                                 float weight) {
  const float r = reflective_base_prior(CudaBackend{}, C_b, R, v_C, v_C_r, weight);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
  return r;
}
float ssim_cuda(int w, int h, Span<const float> x, Span<const float> y, Span<float> v_x, float weight,
                SsimWindow<float> win, Span<float> scratch) {
  const float r = ssim(CudaBackend{}, w, h, x, y, v_x, weight, win, scratch);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
  return r;
}
float sobel_l1_loss_cuda(int w, int h, Span<const float> x, Span<float> v_x, float weight, Span<int8_t> signs) {
  const float r = sobel_l1_loss_elements(CudaBackend{}, w, h, x, v_x, weight, signs);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
  return r;
}

}  // namespace rrg::kernel
