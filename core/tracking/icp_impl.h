#pragma once
// The body of the ICP reduction (icp.h), templated on the back-end tag; instantiated by
// icp_cpu.cpp and icp_cuda.cu.
#include "core/tracking/icp_device.h"

namespace rrg::kernel {

template <class Backend>
IcpSystem reduce_icp(Backend backend, const IcpArgs& a) {
  const IcpArgs args = a;
  return parallel_reduce(backend, args.src_vertices.size(), icp_system_zero(),
                         [=] RRG_HD(int64_t i) { return icp_pixel(args, i); }, IcpSystemSum{});
}

IcpSystem reduce_icp_cpu(const IcpArgs& a);
IcpSystem reduce_icp_cuda(const IcpArgs& a);

}  // namespace rrg::kernel
