#pragma once
// CUDA-only gradient accumulation for the backward rasterisers (gsplat style): lanes of a warp that
// hold the same Gaussian are grouped (cooperative groups labeled_partition), their gradients summed
// with warp shuffles, and one lane does one atomic add per field. Same result as the CPU's plain
// atomics up to float summation order. Only for .cu files.
#include "core/common/hd.h"
#include "core/common/parallel_for_cuda.cuh"
#include "core/render/splat.h"
#include "core/render/splat_grad_ops.h"

#include <cooperative_groups.h>
#include <cooperative_groups/reduce.h>

namespace rrg {

RRG_HD inline void accumulate_grad(CudaBackend, kernel::SplatGrad* dst, const kernel::SplatGrad& g) {
#ifdef __CUDA_ARCH__
  namespace cg = cooperative_groups;
  // Converged lanes vote first: a warp whose lanes all hold zero gradients (alpha skipped) leaves.
  if (__ballot_sync(__activemask(), !kernel::is_zero(g)) == 0) return;
  const cg::coalesced_group active = cg::coalesced_threads();
  const cg::coalesced_group same = cg::labeled_partition(active, static_cast<unsigned long long>(
                                                                     reinterpret_cast<uintptr_t>(dst)));
  const float* s = &g.mean[0];
  float* d = &dst->mean[0];
  for (int k = 0; k < int(sizeof(kernel::SplatGrad) / sizeof(float)); ++k) {
    const float sum = cg::reduce(same, s[k], cg::plus<float>());
    if (same.thread_rank() == 0 && sum != 0.0f) atomicAdd(d + k, sum);
  }
#else
  (void)dst;
  (void)g;
#endif
}

}  // namespace rrg
