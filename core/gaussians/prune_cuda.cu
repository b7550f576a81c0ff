#include "core/common/parallel_for_cuda.cuh"
#include "core/gaussians/prune_impl.h"

namespace rrg::kernel {

void prune_mask_cuda(const PruneArgs& a, Span<const Eigen::Vector3f> means, Span<const Eigen::Vector3f> log_scales,
                     Span<const Eigen::Vector4f> quats, Span<const float> logit_opacities, Span<uint8_t> keep) {
  prune_mask(CudaBackend{}, a, means, log_scales, quats, logit_opacities, keep);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
