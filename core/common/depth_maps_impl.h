#pragma once
// The body of compute_vertex_normal_maps, templated on the back-end tag; instantiated by
// depth_maps_cpu.cpp and depth_maps_cuda.cu.
#include "core/common/depth_maps_device.h"

namespace rrg::kernel {

// V from depth, N from the vertices of normal_depth, in one pass; N is 0 where depth has no vertex.
template <class Backend>
void vertex_normal_maps(Backend backend, ImageView<const float> depth, ImageView<const float> normal_depth,
                        Intrinsics K, ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  const int w = depth.width;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    const int x = int(i % w), y = int(i / w);
    const Eigen::Vector3f v = vertex_at(depth, K, x, y);
    vertices[i] = v;
    normals[i] = v.z() > 0.0f ? normal_at(normal_depth, K, x, y) : Eigen::Vector3f::Zero();
  });
}

void vertex_normal_maps_cpu(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                            ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);
void vertex_normal_maps_cuda(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                             ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);

}  // namespace rrg::kernel
