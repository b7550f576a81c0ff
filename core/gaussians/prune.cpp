#include "core/gaussians/prune.h"

#include "core/common/dispatch.h"
#include "core/gaussians/prune_impl.h"

#include <stdexcept>
#include <string>

namespace rrg {

void PruneParams::validate() const {
  if (!(min_opacity >= 0.0f && min_opacity < 1.0f))
    throw std::invalid_argument("PruneParams: min_opacity = " + std::to_string(min_opacity) + " outside [0, 1)");
  if (!(min_scale >= 0.0f)) throw std::invalid_argument("PruneParams: min_scale = " + std::to_string(min_scale) + " < 0");
  if (!(max_scale > min_scale))
    throw std::invalid_argument("PruneParams: max_scale = " + std::to_string(max_scale) + " <= min_scale");
}

std::vector<uint8_t> prune_mask(const GaussianSet& set, const PruneParams& p) {
  p.validate();
  if (set.size() == 0) return {};
  Buffer<uint8_t> keep(set.size(), set.device());
  const kernel::PruneArgs a{p.min_opacity, p.min_scale, p.max_scale};
  RRG_DISPATCH(set.device(),
               kernel::prune_mask_cpu(a, set.means(), set.log_scales(), set.quats(), set.logit_opacities(), keep.span()),
               kernel::prune_mask_cuda(a, set.means(), set.log_scales(), set.quats(), set.logit_opacities(), keep.span()));
  return keep.to_host();
}

}  // namespace rrg
