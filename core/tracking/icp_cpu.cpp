#include "core/common/parallel_for.h"
#include "core/tracking/icp_impl.h"

namespace rrg::kernel {

IcpSystem reduce_icp_cpu(const IcpArgs& a) { return reduce_icp_tasks(CpuBackend{}, a); }

}  // namespace rrg::kernel
