#include "core/common/parallel_for.h"
#include "core/gaussians/prune_impl.h"

namespace rrg::kernel {

void prune_mask_cpu(const PruneArgs& a, Span<const Eigen::Vector3f> means, Span<const Eigen::Vector3f> log_scales,
                    Span<const Eigen::Vector4f> quats, Span<const float> logit_opacities, Span<uint8_t> keep) {
  prune_mask(CpuBackend{}, a, means, log_scales, quats, logit_opacities, keep);
}

}  // namespace rrg::kernel
