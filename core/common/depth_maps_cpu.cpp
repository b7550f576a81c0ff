#include "core/common/depth_maps_impl.h"
#include "core/common/parallel_for.h"

namespace rrg::kernel {

void vertex_normal_maps_cpu(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                            ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  vertex_normal_maps(CpuBackend{}, depth, normal_depth, K, vertices, normals);
}

}  // namespace rrg::kernel
