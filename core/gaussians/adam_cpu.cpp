#include "core/common/parallel_for.h"
#include "core/gaussians/adam_impl.h"

namespace rrg::kernel {

int64_t adam_step_cpu(int64_t n, const AdamArgs& a, const AdamTensors& t) { return adam_step(CpuBackend{}, n, a, t); }

}  // namespace rrg::kernel
