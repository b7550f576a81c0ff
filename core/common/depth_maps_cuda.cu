#include "core/common/depth_maps_impl.h"
#include "core/common/parallel_for_cuda.cuh"

namespace rrg::kernel {

void vertex_normal_maps_cuda(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                             ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  vertex_normal_maps(CudaBackend{}, depth, normal_depth, K, vertices, normals);
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

}  // namespace rrg::kernel
