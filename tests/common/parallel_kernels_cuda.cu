#include "core/common/parallel_for_cuda.cuh"
#include "tests/common/parallel_kernels_impl.h"

namespace rrg::test::kernel {
void saxpy_cuda(float a, Span<const float> x, Span<float> y) {
  saxpy(CudaBackend{}, a, x, y);
  RRG_CUDA_CHECK(cudaDeviceSynchronize());
}
Moments positive_moments_cuda(Span<const float> x) { return positive_moments(CudaBackend{}, x); }
int64_t index_sum_cuda(int64_t n) { return index_sum(CudaBackend{}, n); }
}  // namespace rrg::test::kernel
