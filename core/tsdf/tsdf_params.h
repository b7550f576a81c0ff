#pragma once
// Parameters of the augmented TSDF volume S (paper §3.1, §4.1.4; DESIGN.md §5) with the paper's
// defaults next to their symbols.
#include "core/common/depth_noise_model.h"
#include "core/tsdf/truncation_band.h"

#include <cstdint>
#include <string>

namespace rrg {

struct TsdfParams {
  float voxel_size = 0.005f;     // s: 0.5 cm (1 cm for rooms of 100 m² and more)
  float truncation = 0.02f;      // ε: 2 cm, as GPS-SLAM
  float band_sigmas = 3.0f;      // k of the band ε(d) = max(ε, k σ_n(d)) (truncation_band.h); 0: ε
  DepthNoiseModel noise;         // σ_n(d) of the band (sessions set planes.segmentation's)
  int max_weight = 100;          // W_max: the running averages become moving averages beyond it
  int reflection_window = 5;     // W: r(p) is the plain mean of the first W predicted masks, then an
                                 // exponential average with factor 1/W (the 5-window vote of §4.1.3)
  float min_depth = 0.1f;        // depth observations (and raycast range) outside [min, max] are
  float max_depth = 10.0f;       // ignored, metres
  int64_t initial_blocks = 4096; // first hash/pool size; both grow on the host between frames

  TruncationBand band() const { return {truncation, band_sigmas, noise}; }

  // Throws std::invalid_argument naming the first bad field.
  void validate() const;
  std::string to_string() const;
};

}  // namespace rrg
