#include "core/common/depth_maps_impl.h"
#include "core/common/parallel_for.h"

namespace rrg::kernel {

void vertex_normal_maps_cpu(ImageView<const float> depth, const Intrinsics& K,
                            ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  vertex_normal_maps(CpuBackend{}, depth, K, vertices, normals);
}

}  // namespace rrg::kernel
