#include "core/common/parallel_for_cuda.cuh"
#include "core/gaussians/adam_impl.h"

namespace rrg::kernel {

// parallel_reduce returns after the GPU work is done.
int64_t adam_step_cuda(int64_t n, const AdamArgs& a, const AdamTensors& t) { return adam_step(CudaBackend{}, n, a, t); }

}  // namespace rrg::kernel
