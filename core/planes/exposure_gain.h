#pragma once
// The exposure of an identification frame relative to the map, for the variance statistic of
// reflective-plane verification (paper §4.1.3, supplement "TSDF Color Variance Update").
// The variance check reads the temporal variance of x = (r + g + b) / 3 at each voxel: a plane is
// reflective when its appearance changes with the view. A camera with auto-exposure changes every
// surface's x with the frame (7-Scenes redkitchen: 0.86–1.34 between frames 20 apart), which the
// Welford statistic takes for view dependence on every bright plane. The gain g of a frame against
// the map's colour C_t at the same pose, over the pixels where both see the same diffuse surface,
// takes that out: fusion feeds x / g to the statistic (ReflectionObservation::exposure_gain).
//   g = exp(median_u(ln x_frame(u) − ln x_map(u)))
// over pixels u with valid depth in both, |D_k(u) − D_t(u)| within `max_depth_difference`, the map's
// reflection mask R(u) = 0 (a reflective surface's x changes with the view by definition), and both
// intensities inside [min_intensity, max_intensity] (the ratio of dark pixels is noise; bright ones
// may be clipped). The median ignores view-dependent pixels while they are fewer than half.
#include "core/common/image.h"
#include "core/tsdf/tsdf_raycast.h"

namespace rrg {

struct ExposureGainParams {
  float min_intensity = 0.05f;
  float max_intensity = 0.95f;
  float max_depth_difference = 0.02f;  // metres; the session passes the TSDF truncation
  int min_pixels = 500;                // fewer agreeing pixels: no estimate (g = 1)
  int stride = 2;                      // every stride-th pixel on both axes
};

struct ExposureGain {
  float gain = 1.0f;      // frame intensity ≈ gain · map intensity
  int pixels = 0;         // pixels the median was taken over
  bool estimated = false; // false: too few pixels; gain is 1
};

// Throws std::invalid_argument when the images' sizes differ, or for a stride < 1 or an empty
// intensity range. The map images are the raycast's C_t, D_t and R at the frame's pose.
ExposureGain estimate_exposure_gain(const ColorImage& frame_color, const DepthImage& frame_depth,
                                    const ColorImage& map_color, const DepthImage& map_depth,
                                    const MaskImage& map_reflection, const ExposureGainParams& params = {});

// The same against a raycast at the frame's pose that computed C_t and the reflection maps, with
// depths agreeing within max_depth_difference (callers pass the TSDF truncation).
ExposureGain estimate_exposure_gain(const ColorImage& frame_color, const DepthImage& frame_depth,
                                    const RaycastResult& map, float max_depth_difference);

}  // namespace rrg
