#pragma once
// The body of raycast() (tsdf_raycast.h), templated on the back-end tag; instantiated by
// tsdf_raycast_cpu.cpp and tsdf_raycast_cuda.cu.
#include "core/tsdf/tsdf_raycast_device.h"

namespace rrg::kernel {

struct RaycastArgs {
  VolumeView volume;
  Intrinsics K;
  Eigen::Matrix3f R_wc;
  Eigen::Vector3f t_wc;
  float truncation, min_depth, max_depth;
  Span<const int32_t> remap;
  ImageView<float> depth;
  ImageView<Eigen::Vector3f> vertices, normals, colors;
  ImageView<int32_t> plane_ids;
  ImageView<float> reflection;
  ImageView<uint8_t> mask;
  ImageView<float> variance;
};

template <class Backend>
void raycast(Backend backend, const RaycastArgs& a) {
  const RaycastArgs args = a;
  const int w = a.depth.width;
  parallel_for(backend, a.depth.size(), [=] RRG_HD(int64_t i) {
    const float x = float(i % w), y = float(i / w);
    const Eigen::Vector3f d = args.R_wc * args.K.unproject(x, y, 1.0f);
    const RayHit hit = march(args.volume, args.t_wc, d, args.truncation, args.min_depth, args.max_depth);
    SurfaceSample s;
    if (hit.hit) s = shade(args.volume, hit.p_w, args.remap);
    args.depth[i] = hit.hit ? hit.z : 0.0f;
    args.vertices[i] = hit.p_w;
    args.normals[i] = s.normal;
    args.colors[i] = s.color;
    args.plane_ids[i] = s.plane;
    args.reflection[i] = s.reflection;
    args.mask[i] = s.reflection > 0.5f ? 1 : 0;
    args.variance[i] = s.variance;
  });
}

void raycast_cpu(const RaycastArgs& a);
void raycast_cuda(const RaycastArgs& a);

}  // namespace rrg::kernel
