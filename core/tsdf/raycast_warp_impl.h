#pragma once
// The body of warp_plane_ids (raycast_warp.h), templated on the back end; instantiated by
// raycast_warp_cpu.cpp and raycast_warp_cuda.cu.
#include "core/common/atomics.h"
#include "core/common/camera.h"
#include "core/common/fast_math.h"
#include "core/common/image.h"
#include "core/common/parallel_for.h"
#include "core/common/span.h"
#include "core/tsdf/tsdf_range_device.h"  // float_bits

#include <Eigen/Core>

namespace rrg::kernel {

struct PlaneWarpArgs {
  ImageView<const float> depth;                // source D (0: no hit)
  ImageView<const Eigen::Vector3f> vertices;   // source V*, world frame
  ImageView<const int32_t> ids;                // source I
  Intrinsics K;                                // target camera
  Eigen::Matrix3f R_cw;
  Eigen::Vector3f t_cw;
  Span<uint64_t> zbuffer;                      // [K.width * K.height]
  ImageView<int32_t> out;                      // target I
};

inline constexpr uint64_t kNoHit = ~uint64_t(0);
inline constexpr float kOnCentre = 1e-3f;  // pixels

// Two passes: every hit min-writes (depth bits << 32 | source index) into the pixels around its
// projection (positive floats order as their bits, so the nearest hit wins, ties to the lower
// index: the result does not depend on the order of the writes), then each pixel takes its
// winner's id.
template <class Backend>
void warp_plane_ids(Backend backend, const PlaneWarpArgs& a) {
  const PlaneWarpArgs args = a;
  const int64_t n_out = int64_t(a.K.width) * a.K.height;
  parallel_for(backend, n_out, [=] RRG_HD(int64_t i) { args.zbuffer[i] = kNoHit; });
  parallel_for(backend, int64_t(a.depth.width) * a.depth.height, [=] RRG_HD(int64_t i) {
    if (!(args.depth[i] > 0.0f)) return;
    const Eigen::Vector3f p = args.R_cw * args.vertices[i] + args.t_cw;
    if (!(p.z() > 0.0f)) return;
    const Eigen::Vector2f uv = args.K.project(p);
    if (!(uv.x() > -1.0f && uv.y() > -1.0f && uv.x() < float(args.K.width) && uv.y() < float(args.K.height)))
      return;
    // The pixel centres within one pixel: floor and floor + 1, or the one centre the point is on
    // (within kOnCentre: a source pixel's own point comes back a little off its centre after the
    // round trip through the world frame, and the same camera must give the source back).
    int x0 = floor_to_int(uv.x()), y0 = floor_to_int(uv.y()), x1 = x0 + 1, y1 = y0 + 1;
    if (uv.x() - float(x0) < kOnCentre) x1 = x0;
    else if (float(x1) - uv.x() < kOnCentre) x0 = x1;
    if (uv.y() - float(y0) < kOnCentre) y1 = y0;
    else if (float(y1) - uv.y() < kOnCentre) y0 = y1;
    const uint64_t key = (uint64_t(uint32_t(float_bits(p.z()))) << 32) | uint64_t(uint32_t(i));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        if (args.out.contains(x, y)) atomic_min(&args.zbuffer[int64_t(y) * args.K.width + x], key);
  });
  parallel_for(backend, n_out, [=] RRG_HD(int64_t i) {
    const uint64_t key = args.zbuffer[i];
    args.out[i] = key == kNoHit ? 0 : args.ids[int64_t(key & 0xffffffffu)];
  });
}

void warp_plane_ids_cpu(const PlaneWarpArgs& a);
void warp_plane_ids_cuda(const PlaneWarpArgs& a);

}  // namespace rrg::kernel
