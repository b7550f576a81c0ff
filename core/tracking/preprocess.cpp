#include "core/tracking/preprocess.h"

#include "core/common/dispatch.h"
#include "core/tracking/preprocess_impl.h"

#include <stdexcept>
#include <string>

namespace rrg {

DeviceImage<float> bilateral_filter_depth(const DeviceImage<float>& depth, int radius, float sigma_space_px,
                                          float sigma_depth_m) {
  if (radius < 1 || !(sigma_space_px > 0) || !(sigma_depth_m > 0))
    throw std::invalid_argument("bilateral_filter_depth: radius must be >= 1 and sigmas > 0");
  DeviceImage<float> out(depth.width(), depth.height(), depth.device());
  RRG_DISPATCH(depth.device(), kernel::bilateral_cpu(depth.view(), out.view(), radius, sigma_space_px, sigma_depth_m),
               kernel::bilateral_cuda(depth.view(), out.view(), radius, sigma_space_px, sigma_depth_m));
  return out;
}

DeviceImage<float> downsample_depth(const DeviceImage<float>& depth, float sigma_depth_m) {
  DeviceImage<float> out((depth.width() + 1) / 2, (depth.height() + 1) / 2, depth.device());
  RRG_DISPATCH(depth.device(), kernel::downsample_cpu(depth.view(), out.view(), 3.0f * sigma_depth_m),
               kernel::downsample_cuda(depth.view(), out.view(), 3.0f * sigma_depth_m));
  return out;
}

// Intrinsics of the half-resolution level: source pixels 2x and 2x+1 average to x, so the
// centre maps as c' = (c + 0.5) / 2 - 0.5 whatever the parity of the size.
Intrinsics half_intrinsics(const Intrinsics& K, int width, int height) {
  return {0.5f * K.fx, 0.5f * K.fy, 0.5f * (K.cx + 0.5f) - 0.5f, 0.5f * (K.cy + 0.5f) - 0.5f, width, height};
}

FramePyramid build_pyramid(const DeviceImage<float>& depth, const Intrinsics& K, const PreprocessParams& params) {
  if (depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument("build_pyramid: depth is " + std::to_string(depth.width()) + "x" +
                                std::to_string(depth.height()) + " but intrinsics are " + K.to_string());
  if (params.levels < 1) throw std::invalid_argument("build_pyramid: levels must be >= 1");
  FramePyramid pyramid;
  DeviceImage<float> d0(depth.width(), depth.height(), depth.device());
  mem::copy(d0.buffer().data(), d0.device(), depth.buffer().data(), depth.device(), depth.buffer().size() * sizeof(float));
  DeviceImage<float> f0;
  if (params.bilateral)
    f0 = bilateral_filter_depth(depth, params.bilateral_radius, params.sigma_space_px, params.sigma_depth_m);
  pyramid.levels.push_back({K, std::move(d0), std::move(f0), {}});
  for (int l = 1; l < params.levels; ++l) {
    const PyramidLevel& prev = pyramid.levels.back();
    DeviceImage<float> half = downsample_depth(prev.depth, params.sigma_depth_m);
    DeviceImage<float> half_filtered;
    if (prev.filtered.width() > 0) half_filtered = downsample_depth(prev.filtered, params.sigma_depth_m);
    const Intrinsics Kl = half_intrinsics(prev.K, half.width(), half.height());
    pyramid.levels.push_back({Kl, std::move(half), std::move(half_filtered), {}});
  }
  for (PyramidLevel& level : pyramid.levels)
    level.maps = compute_vertex_normal_maps(level.depth, level.normal_depth(), level.K);
  return pyramid;
}

}  // namespace rrg
