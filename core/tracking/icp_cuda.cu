#include "core/common/parallel_for_cuda.cuh"
#include "core/tracking/icp_impl.h"

namespace rrg::kernel {

IcpSystem reduce_icp_cuda(const IcpArgs& a) { return reduce_icp(CudaBackend{}, a); }

}  // namespace rrg::kernel
