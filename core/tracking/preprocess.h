#pragma once
// Input preprocessing of tracking (paper §4.1.1): optional bilateral filter of D_k, a depth
// pyramid (2x2 block averages that skip depth discontinuities), and per level the local vertex map
// V_k^l and normal map N_k^l (core/common/depth_maps.h). Runs on the device the depth lives on.
// V_k^l comes from the sensor's depth and N_k^l from the filtered one: the filter smooths in pixels,
// so it rounds a crease over more metres at 4 m than at 1 m, and filtered positions disagree from
// view to view (a 0.6 % scale drift of ICP in a 12 m room); its normals only tilt there
// (docs/tracking.md "Positions from the sensor, normals from the filter").
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/common/depth_maps.h"
#include "core/tracking/tracking_params.h"

#include <vector>

namespace rrg {

struct PyramidLevel {
  Intrinsics K;                    // K scaled to this level
  DeviceImage<float> depth;        // metres, 0 = invalid: the sensor's D_k (level 0) and its averages
  DeviceImage<float> filtered;     // the bilateral-filtered D_k and its averages; empty without the filter
  VertexNormalMaps maps;           // V_k^l from depth, N_k^l from filtered (from depth without it), camera frame

  // The depth N_k^l is computed from: filtered, or depth when the filter is off.
  const DeviceImage<float>& normal_depth() const { return filtered.width() > 0 ? filtered : depth; }
};

struct FramePyramid {
  std::vector<PyramidLevel> levels;  // [0] = full resolution
};

// Bilateral filter (window 2r+1, σ_s pixels, σ_d metres); invalid pixels stay invalid and never
// contribute.
DeviceImage<float> bilateral_filter_depth(const DeviceImage<float>& depth, int radius, float sigma_space_px,
                                          float sigma_depth_m);

// Level 0's filtered depth of build_pyramid into `out` (its image kept where size and device
// match): the bilateral filter with params' window and sigmas. Returns false, leaving `out` empty,
// when params.bilateral is off. Fusion with given poses (no tracker ran) takes its normals from it,
// as tracked fusion does (Tracker::normal_depth() says why).
bool filter_depth_into(DeviceImage<float>& out, const DeviceImage<float>& depth, const PreprocessParams& params);

// Half resolution: mean of the valid pixels of each 2x2 block within 3σ_d of its top-left pixel.
DeviceImage<float> downsample_depth(const DeviceImage<float>& depth, float sigma_depth_m);

// Intrinsics of the level downsample_depth() makes from a K-sized image.
Intrinsics half_intrinsics(const Intrinsics& K, int width, int height);

// The whole preprocessing. Throws std::invalid_argument when depth and K disagree in size.
FramePyramid build_pyramid(const DeviceImage<float>& depth, const Intrinsics& K, const PreprocessParams& params);
// The same into `pyramid`, keeping its images where size and device match: a tracker preprocesses
// every frame into one pyramid, and on the CUDA back end each fresh image is a cudaMalloc/cudaFree.
void build_pyramid_into(FramePyramid& pyramid, const DeviceImage<float>& depth, const Intrinsics& K,
                        const PreprocessParams& params);

}  // namespace rrg
