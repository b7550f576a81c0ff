#include "core/tracking/preprocess.h"

#include "core/common/dispatch.h"
#include "core/tracking/preprocess_impl.h"

#include <stdexcept>
#include <string>

namespace rrg {

namespace {

void bilateral_into(DeviceImage<float>& out, const DeviceImage<float>& depth, int radius, float sigma_space_px,
                    float sigma_depth_m) {
  if (radius < 1 || !(sigma_space_px > 0) || !(sigma_depth_m > 0))
    throw std::invalid_argument("bilateral_filter_depth: radius must be >= 1 and sigmas > 0");
  out.ensure(depth.width(), depth.height(), depth.device());
  RRG_DISPATCH(depth.device(), kernel::bilateral_cpu(depth.view(), out.view(), radius, sigma_space_px, sigma_depth_m),
               kernel::bilateral_cuda(depth.view(), out.view(), radius, sigma_space_px, sigma_depth_m));
}

void downsample_into(DeviceImage<float>& out, const DeviceImage<float>& depth, float sigma_depth_m) {
  out.ensure((depth.width() + 1) / 2, (depth.height() + 1) / 2, depth.device());
  RRG_DISPATCH(depth.device(), kernel::downsample_cpu(depth.view(), out.view(), 3.0f * sigma_depth_m),
               kernel::downsample_cuda(depth.view(), out.view(), 3.0f * sigma_depth_m));
}

}  // namespace

DeviceImage<float> bilateral_filter_depth(const DeviceImage<float>& depth, int radius, float sigma_space_px,
                                          float sigma_depth_m) {
  DeviceImage<float> out;
  bilateral_into(out, depth, radius, sigma_space_px, sigma_depth_m);
  return out;
}

bool filter_depth_into(DeviceImage<float>& out, const DeviceImage<float>& depth, const PreprocessParams& params) {
  if (!params.bilateral) {
    out = DeviceImage<float>();
    return false;
  }
  bilateral_into(out, depth, params.bilateral_radius, params.sigma_space_px, params.sigma_depth_m);
  return true;
}

DeviceImage<float> downsample_depth(const DeviceImage<float>& depth, float sigma_depth_m) {
  DeviceImage<float> out;
  downsample_into(out, depth, sigma_depth_m);
  return out;
}

// Intrinsics of the half-resolution level: source pixels 2x and 2x+1 average to x, so the
// centre maps as c' = (c + 0.5) / 2 - 0.5 whatever the parity of the size.
Intrinsics half_intrinsics(const Intrinsics& K, int width, int height) {
  return {0.5f * K.fx, 0.5f * K.fy, 0.5f * (K.cx + 0.5f) - 0.5f, 0.5f * (K.cy + 0.5f) - 0.5f, width, height};
}

void build_pyramid_into(FramePyramid& pyramid, const DeviceImage<float>& depth, const Intrinsics& K,
                        const PreprocessParams& params) {
  if (depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument("build_pyramid: depth is " + std::to_string(depth.width()) + "x" +
                                std::to_string(depth.height()) + " but intrinsics are " + K.to_string());
  if (params.levels < 1) throw std::invalid_argument("build_pyramid: levels must be >= 1");
  pyramid.levels.resize(size_t(params.levels));
  PyramidLevel& l0 = pyramid.levels[0];
  l0.K = K;
  l0.depth.ensure(depth.width(), depth.height(), depth.device());
  mem::copy(l0.depth.buffer().data(), l0.depth.device(), depth.buffer().data(), depth.device(),
            depth.buffer().size() * sizeof(float));
  filter_depth_into(l0.filtered, depth, params);
  for (size_t l = 1; l < pyramid.levels.size(); ++l) {
    const PyramidLevel& prev = pyramid.levels[l - 1];
    PyramidLevel& level = pyramid.levels[l];
    downsample_into(level.depth, prev.depth, params.sigma_depth_m);
    if (prev.filtered.width() > 0)
      downsample_into(level.filtered, prev.filtered, params.sigma_depth_m);
    else
      level.filtered = DeviceImage<float>();
    level.K = half_intrinsics(prev.K, level.depth.width(), level.depth.height());
  }
  for (PyramidLevel& level : pyramid.levels)
    compute_vertex_normal_maps_into(level.maps, level.depth, level.normal_depth(), level.K);
}

FramePyramid build_pyramid(const DeviceImage<float>& depth, const Intrinsics& K, const PreprocessParams& params) {
  FramePyramid pyramid;
  build_pyramid_into(pyramid, depth, K, params);
  return pyramid;
}

}  // namespace rrg
