#include "core/tsdf/raycast_warp.h"

#include "core/common/dispatch.h"
#include "core/tsdf/raycast_warp_impl.h"

#include <stdexcept>

namespace rrg {

void warp_plane_ids(const RaycastResult& source, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                    DeviceImage<int32_t>& out, Buffer<uint64_t>& zbuffer) {
  if (!K.valid()) throw std::invalid_argument("warp_plane_ids: invalid intrinsics " + K.to_string());
  const int w = source.depth.width(), h = source.depth.height();
  if (w == 0 || source.vertices.width() != w || source.vertices.height() != h || source.plane_ids.width() != w ||
      source.plane_ids.height() != h)
    throw std::invalid_argument("warp_plane_ids: the source raycast needs depth, vertices and plane ids of one size");
  const Device& dev = source.depth.device();
  out.ensure(K.width, K.height, dev);
  const size_t n = size_t(K.width) * size_t(K.height);
  if (zbuffer.size() != n || zbuffer.device() != dev) zbuffer = Buffer<uint64_t>(n, dev);
  const Eigen::Matrix3f R_cw = T_wc.linear().transpose();
  const kernel::PlaneWarpArgs a{source.depth.view(), source.vertices.view(), source.plane_ids.view(), K, R_cw,
                                -(R_cw * T_wc.translation()), zbuffer.span(), out.view()};
  RRG_DISPATCH(dev, kernel::warp_plane_ids_cpu(a), kernel::warp_plane_ids_cuda(a));
}

}  // namespace rrg
