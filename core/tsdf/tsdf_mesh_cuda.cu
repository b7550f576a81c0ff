#include "core/common/parallel_for_cuda.cuh"
#include "core/tsdf/tsdf_mesh_impl.h"

namespace rrg::kernel {

void mesh_blocks_cuda(const MeshArgs& a) {
  mesh_blocks(CudaBackend{}, a);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
