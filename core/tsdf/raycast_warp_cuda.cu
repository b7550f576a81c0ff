#include "core/common/parallel_for_cuda.cuh"
#include "core/tsdf/raycast_warp_impl.h"

namespace rrg::kernel {

void warp_plane_ids_cuda(const PlaneWarpArgs& a) {
  warp_plane_ids(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
