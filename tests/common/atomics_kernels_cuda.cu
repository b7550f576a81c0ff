#include "core/common/parallel_for_cuda.cuh"
#include "tests/common/atomics_kernels_impl.h"

namespace rrg::test::kernel {
void atomics_cuda(int64_t n, float* f, int32_t* s, int32_t* m, Span<uint64_t> t, int32_t* ins) {
  atomics(CudaBackend{}, n, f, s, m, t, ins);
  RRG_CUDA_CHECK(cudaDeviceSynchronize());
}
}  // namespace rrg::test::kernel
