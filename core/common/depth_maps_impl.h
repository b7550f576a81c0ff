#pragma once
// The body of compute_vertex_normal_maps, templated on the back-end tag; instantiated by
// depth_maps_cpu.cpp and depth_maps_cuda.cu.
#include "core/common/depth_maps_device.h"

namespace rrg::kernel {

template <class Backend>
void vertex_normal_maps(Backend backend, ImageView<const float> depth, Intrinsics K,
                        ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  const int w = depth.width;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    vertices[i] = vertex_at(depth, K, int(i % w), int(i / w));
  });
  ImageView<const Eigen::Vector3f> V = vertices;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    normals[i] = normal_at(V, int(i % w), int(i / w));
  });
}

void vertex_normal_maps_cpu(ImageView<const float> depth, const Intrinsics& K,
                            ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);
void vertex_normal_maps_cuda(ImageView<const float> depth, const Intrinsics& K,
                             ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);

}  // namespace rrg::kernel
