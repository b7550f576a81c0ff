#pragma once
// The body of compute_vertex_normal_maps, templated on the back-end tag; instantiated by
// depth_maps_cpu.cpp and depth_maps_cuda.cu.
#include "core/common/depth_maps_device.h"

namespace rrg::kernel {

// N from the vertices of normal_depth; V from depth (when it is another image, its vertices then
// replace normal_depth's, and N is cleared where depth has none).
template <class Backend>
void vertex_normal_maps(Backend backend, ImageView<const float> depth, ImageView<const float> normal_depth,
                        Intrinsics K, ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals) {
  const int w = depth.width;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    vertices[i] = vertex_at(normal_depth, K, int(i % w), int(i / w));
  });
  ImageView<const Eigen::Vector3f> V = vertices;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    normals[i] = normal_at(V, int(i % w), int(i / w));
  });
  if (depth.data == normal_depth.data) return;
  parallel_for(backend, depth.size(), [=] RRG_HD(int64_t i) {
    vertices[i] = vertex_at(depth, K, int(i % w), int(i / w));
    if (!(vertices[i].z() > 0.0f)) normals[i] = Eigen::Vector3f::Zero();
  });
}

void vertex_normal_maps_cpu(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                            ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);
void vertex_normal_maps_cuda(ImageView<const float> depth, ImageView<const float> normal_depth, const Intrinsics& K,
                             ImageView<Eigen::Vector3f> vertices, ImageView<Eigen::Vector3f> normals);

}  // namespace rrg::kernel
