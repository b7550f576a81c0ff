#include "core/common/parallel_for.h"
#include "tests/common/parallel_kernels_impl.h"

namespace rrg::test::kernel {
void saxpy_cpu(float a, Span<const float> x, Span<float> y) { saxpy(CpuBackend{}, a, x, y); }
Moments positive_moments_cpu(Span<const float> x) { return positive_moments(CpuBackend{}, x); }
int64_t index_sum_cpu(int64_t n) { return index_sum(CpuBackend{}, n); }
}  // namespace rrg::test::kernel
