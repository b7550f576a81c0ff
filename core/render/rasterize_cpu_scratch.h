#pragma once
// Scratch memory of the CPU rasterisation schedule (rasterize_cpu.cpp), owned by the Renderer (one
// per Gaussian set) and reused from render to render.
#include "core/render/splat.h"

#include <cstdint>
#include <vector>

namespace rrg::kernel {

// Pixels [x0, x1) x [y0, y1).
struct PixelRect {
  int x0, y0, x1, y1;
};

// Pass 2 keeps the falloffs of at most this many pairs (256 MB); a render with more evaluates them
// again in the backward (the same values).
inline constexpr int64_t kMaxKeptPairs = int64_t(1) << 26;

struct CpuRasterScratch {
  std::vector<PixelRect> reach;      // per splat: the pixels where its alpha can be non-zero (each
                                     // forward pass writes it, the backward of the same pass reads it)
  // Pass 2, written by base_fwd_cpu for base_bwd_cpu of the same render: the falloff G of every
  // (tile entry, pixel) pair the forward visits, in visiting order, 0 where the splat adds nothing
  // (depth cull, outside its ellipse, alpha below 1/255); pair_offset[t] is tile t's first pair.
  // G is empty when there are more than max_kept_pairs pairs.
  std::vector<int64_t> pair_offset;  // [tiles + 1]
  std::vector<float> G;              // [pairs]
  std::vector<SplatGrad> entries;    // backward: per bin entry, its gradient summed over the tile
  int64_t max_kept_pairs = kMaxKeptPairs;
};

}  // namespace rrg::kernel
