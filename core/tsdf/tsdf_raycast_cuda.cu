#include "core/common/parallel_for_cuda.cuh"
#include "core/tsdf/tsdf_raycast_impl.h"

namespace rrg::kernel {

void raycast_cuda(const RaycastArgs& a) {
  raycast(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
