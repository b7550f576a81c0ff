#pragma once
// The body of raycast() (tsdf_raycast.h), templated on the back-end tag; instantiated by
// tsdf_raycast_cpu.cpp and tsdf_raycast_cuda.cu.
#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_range_device.h"
#include "core/tsdf/tsdf_raycast_device.h"

#include <type_traits>

namespace rrg::kernel {

struct RaycastArgs {
  VolumeView volume;
  Span<const uint64_t> block_keys;  // resident blocks (for the range image)
  Span<const uint32_t> boxes;       // their crossing boxes (TsdfVolume::crossing_boxes)
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

// Pixels per work item of the march: a range tile on the CPU (one thread walks it with one block
// cache), one pixel per GPU thread.
template <class Backend>
struct RaycastRun {
  static constexpr int value = 1;
};
template <>
struct RaycastRun<CpuBackend> {
  static constexpr int value = kRangeTile * kRangeTile;
};

enum class PixelRay { Outside, Miss, March };  // past the image edge; no box in range; a ray to march

// Three passes: clear the range image, splat every resident block's crossing box into it, march
// every pixel within its tile's [near, far] (tsdf_range_device.h), then shade it.
template <class Backend>
void raycast(Backend backend, const RaycastArgs& a) {
  const RaycastArgs args = a;
  const int w = a.depth.width;
  const Eigen::Matrix3f R_cw = a.R_wc.transpose();
  const Eigen::Vector3f t_cw = -(R_cw * a.t_wc);
  parallel_for(backend, int64_t(a.range.tiles_x) * a.range.tiles_y,
               [=] RRG_HD(int64_t t) { range_clear(args.range, t); });
  parallel_for(backend, a.block_keys.size, [=] RRG_HD(int64_t b) {
    range_splat_block(args.range, args.boxes[b], args.block_keys[b], args.volume.voxel_size, args.K, R_cw, t_cw,
                      args.min_depth, args.max_depth);
  });
  // Pixels in range-tile order (kRangeTile² consecutive indices per tile): neighbouring rays meet
  // the same blocks, so they share cache lines on the CPU and memory transactions on the GPU. A work
  // item marches a run of RaycastRun consecutive pixels with one block cache, so the run's rays
  // find most blocks in it instead of the hash table.
  const int h = a.depth.height;
  constexpr int run = RaycastRun<Backend>::value;
  const int64_t tile_px = int64_t(kRangeTile) * kRangeTile;
  const auto write = [=] RRG_HD(int64_t i, const RayHit& hit, BlockCache& cache) {
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
  };
  // Pixel j of the tile-ordered numbering: its image index i, and its ray set up in m when its range
  // tile holds a block (a little slack on the far end for rounding in the splat).
  const auto setup = [=] RRG_HD(int64_t j, int64_t& i, MarchState& m) {
    const int64_t t = j / tile_px, k = j % tile_px;
    const int xi = int(t % args.range.tiles_x) * kRangeTile + int(k % kRangeTile);
    const int yi = int(t / args.range.tiles_x) * kRangeTile + int(k / kRangeTile);
    if (xi >= w || yi >= h) return PixelRay::Outside;
    i = int64_t(yi) * w + xi;
    float near, far;
    range_at(args.range, xi, yi, near, far);
    if (!(near <= far)) return PixelRay::Miss;
    const Eigen::Vector3f d = args.R_wc * args.K.unproject(float(xi), float(yi), 1.0f);
    march_begin(m, args.volume, args.t_wc, d, args.truncation, max_f(near, args.min_depth),
                min_f(far + 0.01f * args.volume.voxel_size, args.max_depth));
    return PixelRay::March;
  };
  if constexpr (std::is_same_v<Backend, CpuBackend>) {
    // A CPU thread marches the run's rays kLanes at a time, one sample of each in turn: a ray's
    // samples form one long chain of dependent loads, and independent chains side by side let the
    // core overlap them. Each ray takes the same samples as on its own (the block cache only saves
    // lookups), then its pixel is shaded and written as on the GPU.
    constexpr int kLanes = 4;
    parallel_for(backend, int64_t(a.range.tiles_x) * a.range.tiles_y * tile_px / run, [=](int64_t item) {
      BlockCache cache;
      int64_t index[run];
      RayHit hits[run];
      MarchState lane[kLanes];
      int ray_of[kLanes];
      int next = 0, active = 0;
      const auto refill = [&](int l) {
        ray_of[l] = -1;
        while (next < run) {
          const int r = next++;
          const PixelRay ray = setup(item * run + r, index[r], lane[l]);
          if (ray == PixelRay::March) {
            ray_of[l] = r;
            ++active;
            return;
          }
          if (ray == PixelRay::Miss) hits[r] = RayHit{};
          else index[r] = -1;
        }
      };
      for (int l = 0; l < kLanes; ++l) refill(l);
      while (active > 0)
        for (int l = 0; l < kLanes; ++l) {
          if (ray_of[l] < 0 || !march_step(args.volume, lane[l], cache)) continue;
          hits[ray_of[l]] = lane[l].hit;
          --active;
          refill(l);
        }
      for (int r = 0; r < run; ++r)
        if (index[r] >= 0) write(index[r], hits[r], cache);
    });
  } else {
    parallel_for(backend, int64_t(a.range.tiles_x) * a.range.tiles_y * tile_px / run, [=] RRG_HD(int64_t item) {
      BlockCache cache;
      for (int r = 0; r < run; ++r) {
        int64_t i;
        MarchState m;
        const PixelRay ray = setup(item * run + r, i, m);
        if (ray == PixelRay::Outside) continue;
        write(i, ray == PixelRay::March ? march_run(args.volume, m, cache) : RayHit{}, cache);
      }
    });
  }
}

void raycast_cpu(const RaycastArgs& a);
void raycast_cuda(const RaycastArgs& a);

}  // namespace rrg::kernel
