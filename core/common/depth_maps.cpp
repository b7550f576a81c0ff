#include "core/common/depth_maps.h"

#include "core/common/depth_maps_impl.h"
#include "core/common/dispatch.h"

#include <stdexcept>

namespace rrg {

void compute_vertex_normal_maps_into(VertexNormalMaps& maps, const DeviceImage<float>& depth,
                                     const DeviceImage<float>& normal_depth, const Intrinsics& K) {
  if (depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument("compute_vertex_normal_maps: depth is " + std::to_string(depth.width()) +
                                "x" + std::to_string(depth.height()) + " but intrinsics are " +
                                K.to_string());
  if (normal_depth.width() != depth.width() || normal_depth.height() != depth.height() ||
      !(normal_depth.device() == depth.device()))
    throw std::invalid_argument("compute_vertex_normal_maps: the normals' depth is " +
                                std::to_string(normal_depth.width()) + "x" + std::to_string(normal_depth.height()) +
                                " on " + normal_depth.device().to_string() + " but the depth is " +
                                std::to_string(depth.width()) + "x" + std::to_string(depth.height()) + " on " +
                                depth.device().to_string());
  const Device& dev = depth.device();
  maps.vertices.ensure(depth.width(), depth.height(), dev);
  maps.normals.ensure(depth.width(), depth.height(), dev);
  RRG_DISPATCH(dev,
               kernel::vertex_normal_maps_cpu(depth.view(), normal_depth.view(), K, maps.vertices.view(),
                                              maps.normals.view()),
               kernel::vertex_normal_maps_cuda(depth.view(), normal_depth.view(), K, maps.vertices.view(),
                                               maps.normals.view()));
}

void compute_vertex_normal_maps_into(VertexNormalMaps& maps, const DeviceImage<float>& depth, const Intrinsics& K) {
  compute_vertex_normal_maps_into(maps, depth, depth, K);
}

VertexNormalMaps compute_vertex_normal_maps(const DeviceImage<float>& depth, const DeviceImage<float>& normal_depth,
                                            const Intrinsics& K) {
  VertexNormalMaps maps;
  compute_vertex_normal_maps_into(maps, depth, normal_depth, K);
  return maps;
}

VertexNormalMaps compute_vertex_normal_maps(const DeviceImage<float>& depth, const Intrinsics& K) {
  return compute_vertex_normal_maps(depth, depth, K);
}

}  // namespace rrg
