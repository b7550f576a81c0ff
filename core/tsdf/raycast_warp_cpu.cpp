#include "core/common/parallel_for.h"
#include "core/tsdf/raycast_warp_impl.h"

namespace rrg::kernel {

void warp_plane_ids_cpu(const PlaneWarpArgs& a) { warp_plane_ids(CpuBackend{}, a); }

}  // namespace rrg::kernel
