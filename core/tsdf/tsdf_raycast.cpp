#include "core/tsdf/tsdf_raycast.h"

#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_raycast_impl.h"

#include <stdexcept>

namespace rrg {

void raycast_into(RaycastResult& r, const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                  std::span<const int32_t> plane_remap, RaycastOutputs outputs) {
  if (!K.valid()) throw std::invalid_argument("raycast: invalid intrinsics " + K.to_string());
  const Device& dev = volume.device();
  const int w = K.width, h = K.height;
  const int wc = outputs.color ? w : 0, hc = outputs.color ? h : 0;
  const int wr = outputs.reflection ? w : 0, hr = outputs.reflection ? h : 0;
  r.depth.ensure(w, h, dev);
  const int wn = outputs.normals ? w : 0, hn = outputs.normals ? h : 0;
  r.vertices.ensure(wn, hn, dev);
  r.normals.ensure(wn, hn, dev);
  r.colors.ensure(wc, hc, dev);
  r.plane_ids.ensure(wr, hr, dev);
  r.reflection.ensure(wr, hr, dev);
  r.reflection_mask.ensure(wr, hr, dev);
  r.color_variance.ensure(wr, hr, dev);
  const auto remap = Buffer<int32_t>::from_host(plane_remap, dev);
  const TsdfParams& p = volume.params();
  const int tiles_x = (w + kernel::kRangeTile - 1) / kernel::kRangeTile;
  const int tiles_y = (h + kernel::kRangeTile - 1) / kernel::kRangeTile;
  Buffer<int32_t> near(size_t(tiles_x) * size_t(tiles_y), dev), far(size_t(tiles_x) * size_t(tiles_y), dev);
  kernel::RaycastArgs a{{volume.hash_view(), volume.geometry(), volume.attributes(), p.voxel_size},
                        volume.block_keys(), volume.crossing_boxes(), K, T_wc.linear(), T_wc.translation(), p.truncation,
                        p.min_depth, p.max_depth, {near.span(), far.span(), tiles_x, tiles_y},
                        remap.span(), r.depth.view(), r.vertices.view(), r.normals.view(), r.colors.view(),
                        r.plane_ids.view(), r.reflection.view(), r.reflection_mask.view(),
                        r.color_variance.view(), outputs.color, outputs.reflection, outputs.normals};
  RRG_DISPATCH(dev, kernel::raycast_cpu(a), kernel::raycast_cuda(a));
}

RaycastResult raycast(const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                      std::span<const int32_t> plane_remap, RaycastOutputs outputs) {
  RaycastResult r;
  raycast_into(r, volume, K, T_wc, plane_remap, outputs);
  return r;
}

}  // namespace rrg
