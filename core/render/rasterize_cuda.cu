#include "core/common/parallel_for_cuda.cuh"
#include "core/render/grad_accumulate.cuh"
#include "core/render/rasterize_impl.h"

namespace rrg::kernel {

void base_fwd_cuda(BaseFwdArgs a) {
  base_fwd(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void base_bwd_cuda(BaseBwdArgs a) {
  base_bwd(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void refl_fwd_cuda(ReflFwdArgs a) {
  refl_fwd(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void refl_bwd_cuda(ReflBwdArgs a) {
  refl_bwd(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void composite_cuda(ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R,
                    ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C) {
  composite(CudaBackend{}, C_b, R, C_r, C);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void composite_bwd_cuda(ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R,
                        ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra,
                        ImageView<Eigen::Vector3f> v_C_r) {
  composite_bwd(CudaBackend{}, v_C, R, v_C_r_extra, has_extra, v_C_r);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

void mask_group_cuda(ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k,
                     ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r) {
  mask_group(CudaBackend{}, I, plane, C_k, W_k, C_r, W_r);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
