#include "core/tsdf/tsdf_params.h"

#include <cmath>
#include <stdexcept>

namespace rrg {

void TsdfParams::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("TsdfParams: " + what); };
  if (!(voxel_size > 0.0f) || !std::isfinite(voxel_size)) bad("voxel_size must be > 0");
  if (!(truncation >= voxel_size)) bad("truncation must be >= voxel_size");
  if (!(band_sigmas >= 0.0f) || !std::isfinite(band_sigmas)) bad("band_sigmas must be finite and >= 0");
  if (!noise.valid()) bad("the noise model must have a, b >= 0 and be finite");
  if (max_weight < 1 || max_weight > 65535) bad("max_weight must be in [1, 65535]");
  if (reflection_window < 1 || reflection_window > 65535) bad("reflection_window must be in [1, 65535]");
  if (!(min_depth >= 0.0f) || !(max_depth > min_depth)) bad("need 0 <= min_depth < max_depth");
  if (initial_blocks < 1) bad("initial_blocks must be >= 1");
}

std::string TsdfParams::to_string() const {
  return "voxel " + std::to_string(voxel_size) + " m, truncation " + std::to_string(truncation) +
         " m (band max(ε, " + std::to_string(band_sigmas) + " σ_n)), max weight " + std::to_string(max_weight) + ", reflection window " +
         std::to_string(reflection_window) + ", depth [" + std::to_string(min_depth) + ", " +
         std::to_string(max_depth) + "] m";
}

}  // namespace rrg
