#include "core/planes/exposure_gain.h"

#include "core/tsdf/voxel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace rrg {

namespace {

template <class A, class B>
void check_same_size(const A& a, const B& b, const char* name) {
  if (a.width() != b.width() || a.height() != b.height())
    throw std::invalid_argument(std::string("estimate_exposure_gain: ") + name + " is " + std::to_string(b.width()) +
                                "x" + std::to_string(b.height()) + ", the frame " + std::to_string(a.width()) + "x" +
                                std::to_string(a.height()));
}

}  // namespace

ExposureGain estimate_exposure_gain(const ColorImage& frame_color, const DepthImage& frame_depth,
                                    const ColorImage& map_color, const DepthImage& map_depth,
                                    const MaskImage& map_reflection, const ExposureGainParams& p) {
  if (p.stride < 1) throw std::invalid_argument("estimate_exposure_gain: stride must be >= 1");
  if (!(p.min_intensity > 0.0f && p.min_intensity < p.max_intensity))
    throw std::invalid_argument("estimate_exposure_gain: need 0 < min_intensity < max_intensity");
  check_same_size(frame_color, frame_depth, "the frame's depth");
  check_same_size(frame_color, map_color, "the map's colour");
  check_same_size(frame_color, map_depth, "the map's depth");
  check_same_size(frame_color, map_reflection, "the map's reflection mask");
  std::vector<float> log_ratio;
  for (int y = 0; y < frame_color.height(); y += p.stride)
    for (int x = 0; x < frame_color.width(); x += p.stride) {
      const float d = frame_depth(x, y), dm = map_depth(x, y);
      if (!(d > 0.0f && dm > 0.0f) || std::fabs(d - dm) > p.max_depth_difference || map_reflection(x, y)) continue;
      const float a = welford_intensity(frame_color(x, y)), b = welford_intensity(map_color(x, y));
      if (a < p.min_intensity || a > p.max_intensity || b < p.min_intensity || b > p.max_intensity) continue;
      log_ratio.push_back(std::log(a) - std::log(b));
    }
  ExposureGain g;
  g.pixels = int(log_ratio.size());
  if (g.pixels < p.min_pixels) return g;
  const auto mid = log_ratio.begin() + ptrdiff_t(log_ratio.size() / 2);
  std::nth_element(log_ratio.begin(), mid, log_ratio.end());
  g.gain = std::exp(*mid);
  g.estimated = true;
  return g;
}

ExposureGain estimate_exposure_gain(const ColorImage& frame_color, const DepthImage& frame_depth,
                                    const RaycastResult& map, float max_depth_difference) {
  ExposureGainParams p;
  p.max_depth_difference = max_depth_difference;
  return estimate_exposure_gain(frame_color, frame_depth, map.colors.to_host(), map.depth.to_host(),
                                map.reflection_mask.to_host(), p);
}

}  // namespace rrg
