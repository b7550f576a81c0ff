#include "core/tsdf/tsdf_integrate.h"

#include "core/common/depth_maps.h"
#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_integrate_impl.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg {
namespace {

template <class T>
void check_image(const DeviceImage<T>& image, const char* what, const Intrinsics& K, const Device& device) {
  if (image.width() != K.width || image.height() != K.height)
    throw std::invalid_argument(std::string("integrate: ") + what + " is " + std::to_string(image.width()) + "x" +
                                std::to_string(image.height()) + " but intrinsics are " + K.to_string());
  if (!(image.device() == device))
    throw std::invalid_argument(std::string("integrate: ") + what + " is on " + image.device().to_string() +
                                " but the volume is on " + device.to_string());
}

template <class ColorT>
int64_t integrate_any(TsdfVolume& volume, const DeviceImage<float>& depth, const DeviceImage<ColorT>& color,
                      const Intrinsics& K, const Eigen::Isometry3f& T_wc, const ReflectionObservation* refl,
                      const DeviceImage<float>* normal_depth) {
  if (!K.valid()) throw std::invalid_argument("integrate: invalid intrinsics " + K.to_string());
  const Device& dev = volume.device();
  check_image(depth, "depth", K, dev);
  check_image(color, "colour", K, dev);
  if (normal_depth) check_image(*normal_depth, "normals' depth", K, dev);
  Buffer<int32_t> remap;
  if (refl) {
    if (!refl->plane_ids || !refl->reflection_mask)
      throw std::invalid_argument("integrate: a reflection observation needs plane ids and a reflection mask");
    check_image(*refl->plane_ids, "plane id image", K, dev);
    check_image(*refl->reflection_mask, "reflection mask", K, dev);
    if (!(std::isfinite(refl->exposure_gain) && refl->exposure_gain > 0.0f))
      throw std::invalid_argument("integrate: exposure gain must be finite and > 0, got " +
                                  std::to_string(refl->exposure_gain));
    remap = Buffer<int32_t>::from_host(refl->plane_remap, dev);
  }
  TsdfVolume::FrameScratch& scratch = volume.frame_scratch();
  compute_vertex_normal_maps_into(scratch.maps, depth, normal_depth ? *normal_depth : depth, K);
  const VertexNormalMaps& maps = scratch.maps;
  const Eigen::Matrix3f R_wc = T_wc.linear();
  const Eigen::Vector3f t_wc = T_wc.translation();
  const TsdfParams& p = volume.params();
  DeviceImage<kernel::FusionPixel>& pixels = scratch.pixels;
  pixels.ensure(K.width, K.height, dev);
  const kernel::FusionPixelArgs pa{depth.view(), maps.normals.view(), K, p.min_depth, p.max_depth, pixels.view()};
  RRG_DISPATCH(dev, kernel::fusion_pixels_cpu(pa), kernel::fusion_pixels_cuda(pa));
  const Span<const int32_t> active = volume.allocate_from_depth(depth, K, R_wc, t_wc);
  const Eigen::Matrix3f R_cw = R_wc.transpose();
  kernel::IntegrateArgs<ColorT> a{pixels.view(), color.view(), K, R_cw, Eigen::Vector3f(-(R_cw * t_wc)),
                                  p.voxel_size, p.band(), p.max_weight, p.reflection_window, active,
                                  volume.block_keys(), volume.geometry(), volume.attributes(),
                                  volume.block_versions(), volume.version(), refl != nullptr,
                                  refl ? 1.0f / refl->exposure_gain : 1.0f,
                                  refl ? refl->plane_ids->view() : ImageView<const int32_t>{},
                                  refl ? refl->reflection_mask->view() : ImageView<const uint8_t>{},
                                  remap.span()};
  RRG_DISPATCH(dev, kernel::integrate_cpu(a), kernel::integrate_cuda(a));
  volume.update_crossing_boxes(active);  // the raycast's range image reads them
  return active.size;
}

}  // namespace

int64_t integrate(TsdfVolume& volume, const DeviceImage<float>& depth, const DeviceImage<Color>& color,
                  const Intrinsics& K, const Eigen::Isometry3f& T_wc, const ReflectionObservation* reflection,
                  const DeviceImage<float>* normal_depth) {
  return integrate_any(volume, depth, color, K, T_wc, reflection, normal_depth);
}

int64_t integrate(TsdfVolume& volume, const DeviceImage<float>& depth, const DeviceImage<Rgb8>& color,
                  const Intrinsics& K, const Eigen::Isometry3f& T_wc, const ReflectionObservation* reflection,
                  const DeviceImage<float>* normal_depth) {
  return integrate_any(volume, depth, color, K, T_wc, reflection, normal_depth);
}

DeviceImage<int32_t> plane_ids_to_device(const LabelImage& labels, const Device& device) {
  Image<int32_t> ids(labels.width(), labels.height());
  for (size_t i = 0; i < labels.size(); ++i) ids[i] = labels[i];
  return DeviceImage<int32_t>::from_host(ids, device);
}

float view_reach(const Intrinsics& K, const TsdfParams& params) {
  const float x = std::max(K.cx, float(K.width) - 1.0f - K.cx) / K.fx;
  const float y = std::max(K.cy, float(K.height) - 1.0f - K.cy) / K.fy;
  const float d = params.max_depth;
  const float half_diagonal = 0.5f * std::sqrt(3.0f) * params.voxel_size * float(kBlockSide);
  return d * std::sqrt(1.0f + x * x + y * y) + params.band().at(d) + half_diagonal;
}

}  // namespace rrg
