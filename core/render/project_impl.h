#pragma once
// Projection, tile binning and the projection backward, templated on the back end; instantiated by
// project_cpu.cpp and project_cuda.cu.
#include "core/common/atomics.h"
#include "core/render/project_device.h"
#include "core/render/splat_grad_ops.h"
#include "core/render/stage_args.h"

#include <cstring>

namespace rrg::kernel {

template <class S>
RRG_HD inline GaussianInT<float, S> gaussian_at(const GaussianViews& g, int64_t i, int stride) {
  return {g.means[i], g.log_scales[i], g.quats[i], g.logit_opacities[i], &g.sh[i * stride]};
}

// splats[i], rects[i] for every Gaussian, one per work item; culled ones get a zero splat and an
// empty rect. The CPU back end runs project_lanes (project_cpu.cpp) instead: the same
// project_gaussian on eight Gaussians at once, bit for bit these results
// (Projection.LanesMatchThePerGaussianLoop).
template <class Backend>
void project_splats(Backend b, View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects) {
  parallel_for(b, g.means.size, [=] RRG_HD(int64_t i) {
    Splat s{};
    float radius = 0;
    if (!centre_in_reach(view, g.means[i]) ||
        !project_gaussian(view, gaussian_at<Eigen::Vector3f>(g, i, view.sh_stride), s, radius)) {
      splats[i] = Splat{};
      rects[i] = TileRect{};
      return;
    }
    splats[i] = s;
    rects[i] = tile_rect(view, s, radius);
  });
}

// counts[i] = tiles touched by Gaussian i, 0 unless plane < 0 or plane_ids[i] == plane.
template <class Backend>
void count_tiles(Backend b, Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane,
                 Span<int32_t> counts) {
  parallel_for(b, rects.size, [=] RRG_HD(int64_t i) {
    counts[i] = (plane < 0 || plane_ids[i] == plane) ? rects[i].count() : 0;
  });
}

// Key of an entry: tile id in the high 32 bits, and with_depth the depth's float bits (positive
// floats order as their bits) in the low 32; value: the Gaussian index.
template <class Backend>
void write_keys(Backend b, int tiles_x, Span<const TileRect> rects, Span<const Splat> splats,
                Span<const int32_t> counts, Span<const int32_t> offsets, bool with_depth,
                Span<uint64_t> keys, Span<int32_t> values) {
  parallel_for(b, rects.size, [=] RRG_HD(int64_t i) {
    if (counts[i] == 0) return;
    const TileRect r = rects[i];
    uint32_t depth_bits = 0;
    if (with_depth) {
      const float d = splats[i].depth;
      memcpy(&depth_bits, &d, sizeof(float));
    }
    int64_t at = offsets[i];
    for (int ty = r.y0; ty < r.y1; ++ty)
      for (int tx = r.x0; tx < r.x1; ++tx, ++at) {
        const uint64_t tile = uint64_t(ty) * uint64_t(tiles_x) + uint64_t(tx);
        keys[at] = with_depth ? (tile << 32) | depth_bits : tile;
        values[at] = int32_t(i);
      }
  });
}

// ranges[t] = [begin, end) of tile t in sorted keys (ranges zeroed beforehand).
template <class Backend>
void tile_ranges(Backend b, Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges) {
  const int64_t n = keys.size;
  parallel_for(b, n, [=] RRG_HD(int64_t i) {
    const int shift = with_depth ? 32 : 0;
    const int32_t tile = int32_t(keys[i] >> shift);
    if (i == 0 || int32_t(keys[i - 1] >> shift) != tile) ranges[tile].begin = int32_t(i);
    if (i == n - 1 || int32_t(keys[i + 1] >> shift) != tile) ranges[tile].end = int32_t(i + 1);
  });
}

// Writes Gaussian i's parameter gradients (SH rows up to the stride) and touched = whether any is
// non-zero.
RRG_HD inline void store_gaussian_grad(const GaussianGradViews& v, int64_t i, int sh_stride, const Vec3<float>& v_mean,
                                       const Vec3<float>& v_log_scale, const Vec4<float>& v_quat, float v_logit,
                                       const Vec3<float>* v_sh) {
  v.v_means[i] = v_mean;
  v.v_log_scales[i] = v_log_scale;
  v.v_quats[i] = v_quat;
  v.v_logit_opacities[i] = v_logit;
  bool nonzero = v_logit != 0.0f;
  for (int c = 0; c < 3; ++c) nonzero = nonzero || v_mean[c] != 0.0f || v_log_scale[c] != 0.0f;
  for (int c = 0; c < 4; ++c) nonzero = nonzero || v_quat[c] != 0.0f;
  for (int k = 0; k < sh_stride; ++k) {
    v.v_sh[i * sh_stride + k] = v_sh[k];
    for (int c = 0; c < 3; ++c) nonzero = nonzero || v_sh[k][c] != 0.0f;
  }
  v.touched[i] = nonzero ? 1 : 0;
}

// Gradients of the Gaussian parameters from the splat gradients, and `touched`. A splat no pixel
// sent gradient to (the part of the map outside the view) has zero parameter gradients: it is marked
// 0 and its v_* entries are not written (GaussianGrads), so an iteration costs nothing per
// Gaussian out of view beyond reading its splat gradient; a map many times the view would
// otherwise write 59 zero floats per Gaussian per iteration.
template <class Backend>
void project_bwd(Backend b, View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  parallel_for(b, g.means.size, [=] RRG_HD(int64_t i) {
    if (is_zero(v_splats[i])) {
      v.touched[i] = 0;
      return;
    }
    Vec3<float> v_sh_local[kMaxShCoeffs];
    for (int k = 0; k < kMaxShCoeffs; ++k) v_sh_local[k].setZero();
    Vec3<float> v_mean = Vec3<float>::Zero(), v_log_scale = Vec3<float>::Zero();
    Vec4<float> v_quat = Vec4<float>::Zero();
    float v_logit = 0;
    if (!project_gaussian_bwd(view, gaussian_at<Eigen::Vector3f>(g, i, view.sh_stride), view.sh_degree, v_splats[i],
                              v_mean, v_log_scale, v_quat, v_logit, v_sh_local)) {
      // culled (never the case for a splat that drew a pixel): no gradient
      v_mean.setZero();
      v_log_scale.setZero();
      v_quat.setZero();
      v_logit = 0;
      for (int k = 0; k < kMaxShCoeffs; ++k) v_sh_local[k].setZero();
    }
    store_gaussian_grad(v, i, view.sh_stride, v_mean, v_log_scale, v_quat, v_logit, v_sh_local);
  });
}

void project_splats_cpu(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects);
// The per-Gaussian loop above on the CPU (what CUDA runs): the reference of the lanes' test.
void project_splats_per_gaussian_cpu(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects);
void project_splats_cuda(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects);
void count_tiles_cpu(Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane, Span<int32_t> counts);
void count_tiles_cuda(Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane, Span<int32_t> counts);
void write_keys_cpu(int tiles_x, Span<const TileRect> rects, Span<const Splat> splats, Span<const int32_t> counts,
                    Span<const int32_t> offsets, bool with_depth, Span<uint64_t> keys, Span<int32_t> values);
void write_keys_cuda(int tiles_x, Span<const TileRect> rects, Span<const Splat> splats, Span<const int32_t> counts,
                     Span<const int32_t> offsets, bool with_depth, Span<uint64_t> keys, Span<int32_t> values);
void tile_ranges_cpu(Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges);
void tile_ranges_cuda(Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges);
void project_bwd_cpu(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v);
// The per-Gaussian loop above on the CPU (what CUDA runs): the reference of the lanes' test.
void project_bwd_per_gaussian_cpu(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v);
void project_bwd_cuda(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v);

}  // namespace rrg::kernel
