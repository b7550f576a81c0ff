#pragma once
// The body of the ICP reduction (icp.h), instantiated by icp_cpu.cpp and icp_cuda.cu. Both back
// ends run the same per-pixel kernel (icp_accumulate, icp_device.h); only the reduction differs:
//   CUDA: parallel_reduce of one IcpSystem per pixel (CUB block reduction);
//   CPU:  fixed tasks of kIcpCpuTaskPixels pixels accumulated in place, summed in task order, so
//         the result does not depend on the thread count and no 240-byte temporary is built and
//         added per pixel.
#include "core/tracking/icp_device.h"

#include <vector>

namespace rrg::kernel {

inline constexpr int64_t kIcpCpuTaskPixels = 2048;

template <class Backend>
IcpSystem reduce_icp(Backend backend, const IcpArgs& a) {
  const IcpArgs args = a;
  return parallel_reduce(backend, args.src_vertices.size(), icp_system_zero(),
                         [=] RRG_HD(int64_t i) { return icp_pixel(args, i); }, IcpSystemSum{});
}

template <class Backend>
IcpSystem reduce_icp_tasks(Backend backend, const IcpArgs& a) {
  const IcpArgs args = a;
  const int64_t n = args.src_vertices.size();
  const int64_t tasks = (n + kIcpCpuTaskPixels - 1) / kIcpCpuTaskPixels;
  std::vector<IcpSystem> partial(size_t(tasks), icp_system_zero());
  IcpSystem* out = partial.data();
  parallel_for(backend, tasks, [=](int64_t t) {
    IcpSystem s = icp_system_zero();
    const int64_t end = std::min(n, (t + 1) * kIcpCpuTaskPixels);
    for (int64_t i = t * kIcpCpuTaskPixels; i < end; ++i) icp_accumulate(args, i, s);
    out[t] = s;
  });
  IcpSystem total = icp_system_zero();
  for (const IcpSystem& s : partial) total = IcpSystemSum{}(total, s);
  return total;
}

IcpSystem reduce_icp_cpu(const IcpArgs& a);
IcpSystem reduce_icp_cuda(const IcpArgs& a);

}  // namespace rrg::kernel
