#include "core/tsdf/tsdf_raycast.h"

#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_raycast_impl.h"

#include <stdexcept>

namespace rrg {

RaycastResult raycast(const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                      std::span<const int32_t> plane_remap) {
  if (!K.valid()) throw std::invalid_argument("raycast: invalid intrinsics " + K.to_string());
  const Device& dev = volume.device();
  const int w = K.width, h = K.height;
  RaycastResult r{DeviceImage<float>(w, h, dev),           DeviceImage<Eigen::Vector3f>(w, h, dev),
                  DeviceImage<Eigen::Vector3f>(w, h, dev), DeviceImage<Eigen::Vector3f>(w, h, dev),
                  DeviceImage<int32_t>(w, h, dev),         DeviceImage<float>(w, h, dev),
                  DeviceImage<uint8_t>(w, h, dev),         DeviceImage<float>(w, h, dev)};
  const auto remap = Buffer<int32_t>::from_host(plane_remap, dev);
  const TsdfParams& p = volume.params();
  const int tiles_x = (w + kernel::kRangeTile - 1) / kernel::kRangeTile;
  const int tiles_y = (h + kernel::kRangeTile - 1) / kernel::kRangeTile;
  Buffer<int32_t> near(size_t(tiles_x) * size_t(tiles_y), dev), far(size_t(tiles_x) * size_t(tiles_y), dev);
  kernel::RaycastArgs a{{volume.hash_view(), volume.geometry(), volume.attributes(), p.voxel_size},
                        volume.block_keys(), K, T_wc.linear(), T_wc.translation(), p.truncation,
                        p.min_depth, p.max_depth, {near.span(), far.span(), tiles_x, tiles_y},
                        remap.span(), r.depth.view(), r.vertices.view(), r.normals.view(), r.colors.view(),
                        r.plane_ids.view(), r.reflection.view(), r.reflection_mask.view(),
                        r.color_variance.view()};
  RRG_DISPATCH(dev, kernel::raycast_cpu(a), kernel::raycast_cuda(a));
  return r;
}

}  // namespace rrg
