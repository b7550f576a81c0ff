#pragma once
// Gaussian pruning (paper §4.2.3, supplement): after each optimisation round a Gaussian is removed
// when its opacity σ = sigmoid(logit) is below min_opacity, or its scale is below min_scale or
// above max_scale. "Scale" is the largest axis max_k exp(log s_k): Gaussians are initialised flat
// along the surface normal (one axis ~10x smaller, by design), so the smallest axis would remove
// every new Gaussian. Gaussians with a non-finite parameter are removed too.
#include "core/gaussians/gaussian_set.h"

#include <cstdint>
#include <vector>

namespace rrg {

struct PruneParams {
  float min_opacity = 0.005f;  // base 0.005, reflection 0.005
  float min_scale = 0.003f;    // base 0.003, reflection 0.005 (metres)
  float max_scale = 0.1f;      // base 0.1, reflection 0.2 (metres)
  static PruneParams base() { return {}; }
  static PruneParams reflection() { return {0.005f, 0.005f, 0.2f}; }
  void validate() const;  // throws std::invalid_argument naming the bad threshold
};

// keep[i] = 1 when Gaussian i survives, on the set's device, returned on the host.
std::vector<uint8_t> prune_mask(const GaussianSet& set, const PruneParams& params);

}  // namespace rrg
