#include "core/common/parallel_for.h"
#include "tests/common/atomics_kernels_impl.h"

namespace rrg::test::kernel {
void atomics_cpu(int64_t n, float* f, int32_t* s, int32_t* m, Span<uint64_t> t, int32_t* ins) {
  atomics(CpuBackend{}, n, f, s, m, t, ins);
}
}  // namespace rrg::test::kernel
