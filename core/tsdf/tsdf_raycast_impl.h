#pragma once
// The body of raycast() (tsdf_raycast.h), templated on the back-end tag; instantiated by
// tsdf_raycast_cpu.cpp and tsdf_raycast_cuda.cu.
#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_range_device.h"
#include "core/tsdf/tsdf_raycast_device.h"

namespace rrg::kernel {

struct RaycastArgs {
  VolumeView volume;
  Span<const uint64_t> block_keys;  // resident blocks (for the range image)
  Intrinsics K;
  Eigen::Matrix3f R_wc;
  Eigen::Vector3f t_wc;
  float truncation, min_depth, max_depth;
  RangeImage range;                 // scratch, [tiles]
  Span<const int32_t> remap;
  ImageView<float> depth;
  ImageView<Eigen::Vector3f> vertices, normals, colors;
  ImageView<int32_t> plane_ids;
  ImageView<float> reflection;
  ImageView<uint8_t> mask;
  ImageView<float> variance;
  bool want_color, want_reflection, want_normals;  // RaycastOutputs: their images are empty when false
};

// Pixels per work item of the march: a row of a range tile on the CPU (one thread walks it with one
// block cache), one pixel per GPU thread.
template <class Backend>
struct RaycastRun {
  static constexpr int value = 1;
};
template <>
struct RaycastRun<CpuBackend> {
  static constexpr int value = kRangeTile;
};

// Three passes: clear the range image, splat every resident block into it, march every pixel
// within its tile's [near, far] (tsdf_range_device.h).
template <class Backend>
void raycast(Backend backend, const RaycastArgs& a) {
  const RaycastArgs args = a;
  const int w = a.depth.width;
  const Eigen::Matrix3f R_cw = a.R_wc.transpose();
  const Eigen::Vector3f t_cw = -(R_cw * a.t_wc);
  parallel_for(backend, int64_t(a.range.tiles_x) * a.range.tiles_y,
               [=] RRG_HD(int64_t t) { range_clear(args.range, t); });
  parallel_for(backend, a.block_keys.size, [=] RRG_HD(int64_t b) {
    range_splat_block(args.range, args.block_keys[b], args.volume.voxel_size, args.K, R_cw, t_cw,
                      args.min_depth, args.max_depth);
  });
  // Pixels in range-tile order (kRangeTile² consecutive indices per tile): neighbouring rays meet
  // the same blocks, so they share cache lines on the CPU and memory transactions on the GPU. A work
  // item marches a run of RaycastRun consecutive pixels with one block cache, so the run's rays
  // find most blocks in it instead of the hash table.
  const int h = a.depth.height;
  constexpr int run = RaycastRun<Backend>::value;
  const int64_t tile_px = int64_t(kRangeTile) * kRangeTile;
  parallel_for(backend, int64_t(a.range.tiles_x) * a.range.tiles_y * tile_px / run, [=] RRG_HD(int64_t item) {
    BlockCache cache;
    for (int r = 0; r < run; ++r) {
      const int64_t j = item * run + r;
      const int64_t t = j / tile_px, k = j % tile_px;
      const int xi = int(t % args.range.tiles_x) * kRangeTile + int(k % kRangeTile);
      const int yi = int(t / args.range.tiles_x) * kRangeTile + int(k / kRangeTile);
      if (xi >= w || yi >= h) continue;
      const int64_t i = int64_t(yi) * w + xi;
      float near, far;
      range_at(args.range, xi, yi, near, far);
      const Eigen::Vector3f d = args.R_wc * args.K.unproject(float(xi), float(yi), 1.0f);
      RayHit hit;
      if (near <= far)  // a little slack on the far end for rounding in the splat
        hit = march(args.volume, args.t_wc, d, args.truncation, max_f(near, args.min_depth),
                    min_f(far + 0.01f * args.volume.voxel_size, args.max_depth), cache);
      SurfaceSample s;
      if (hit.hit)
        s = shade(args.volume, hit.p_w, args.remap, cache, args.want_color, args.want_reflection, args.want_normals);
      args.depth[i] = hit.hit ? hit.z : 0.0f;
      if (args.want_normals) {
        args.vertices[i] = hit.p_w;
        args.normals[i] = s.normal;
      }
      if (args.want_color) args.colors[i] = s.color;
      if (args.want_reflection) {
        args.plane_ids[i] = s.plane;
        args.reflection[i] = s.reflection;
        args.mask[i] = s.reflection > 0.5f ? 1 : 0;
        args.variance[i] = s.variance;
      }
    }
  });
}

void raycast_cpu(const RaycastArgs& a);
void raycast_cuda(const RaycastArgs& a);

}  // namespace rrg::kernel
