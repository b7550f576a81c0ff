#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_raycast_impl.h"

namespace rrg::kernel {

void raycast_cpu(const RaycastArgs& a) { raycast(CpuBackend{}, a); }

}  // namespace rrg::kernel
