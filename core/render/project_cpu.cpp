#include "core/common/parallel_for.h"
#include "core/render/project_impl.h"

#include <algorithm>

namespace rrg::kernel {

namespace {

constexpr int kLanes = 8;  // Gaussians per vector loop (AVX2: eight floats)

constexpr int sh_count(int degree) { return (degree + 1) * (degree + 1); }

// What the vector loops read: the arrays' pointers as locals (loaded from a GaussianViews inside
// the loop they keep it scalar) and the block's SH coefficients copied lane-major (LaneSh): read
// in place, eight rows 16 coefficients apart are a gather GCC does not vectorise.
struct LaneInputs {
  const Eigen::Vector3f* means;
  const Eigen::Vector3f* log_scales;
  const Eigen::Vector4f* quats;
  const float* logits;
  const float* sh;  // [3 K, kLanes]
};

// Gaussian i in lane l of a vector loop: written out in the loop body, in one go, the quaternion
// component by component (a helper returning the record, members assigned afterwards, or a
// Vector4f copy, 4-float packet code, each keep the loop scalar).
#define RRG_LANE_GAUSSIAN(in, i, l)                                                                 \
  GaussianInT<float, Eigen::Vector3f, LaneSh<kLanes>> {                                              \
    (in).means[i], (in).log_scales[i],                                                               \
        Eigen::Vector4f((in).quats[i][0], (in).quats[i][1], (in).quats[i][2], (in).quats[i][3]),     \
        (in).logits[i], LaneSh<kLanes> { (in).sh + (l) }                                             \
  }

template <int D>
LaneInputs lane_inputs(const GaussianViews& g, int64_t i0, int sh_stride, float* sh) {
  for (int l = 0; l < kLanes; ++l) {
    const Eigen::Vector3f* row = &g.sh[(i0 + l) * sh_stride];
    for (int k = 0; k < sh_count(D); ++k)
      for (int c = 0; c < 3; ++c) sh[(3 * k + c) * kLanes + l] = row[k][c];
  }
  return {g.means.data, g.log_scales.data, g.quats.data, g.logit_opacities.data, sh};
}

// Gaussians [i0, i0 + kLanes) of g projected side by side: the loop over the lanes is
// straight-line project_gaussian (no early return; SH degree D a constant, so the SH sums are
// unrolled), which GCC turns into 8-wide vector code once every call in it is inlined
// (core/CMakeLists.txt raises GCC's inlining limits for this file). `GCC ivdep`, not `omp simd`:
// OpenMP's per-lane copies of the loop's local records stay in memory and keep it scalar. A block
// whose centres are all out of reach (most of a map larger than the view) skips the vector loop.
template <int D>
void project_block(const View& view, const GaussianViews& g, int64_t i0, Splat* splats, TileRect* rects) {
  bool any = false;
  for (int l = 0; l < kLanes; ++l) any = any | centre_in_reach(view, g.means[i0 + l]);
  if (!any) {
    std::fill(splats + i0, splats + i0 + kLanes, Splat{});
    std::fill(rects + i0, rects + i0 + kLanes, TileRect{});
    return;
  }
  alignas(32) float sh[3 * sh_count(D) * kLanes];
  const LaneInputs in = lane_inputs<D>(g, i0, view.sh_stride, sh);
  alignas(32) float f[10][kLanes];
  alignas(32) int32_t r[4][kLanes];
  alignas(32) int32_t ok[kLanes];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const auto gi = RRG_LANE_GAUSSIAN(in, i0 + l, l);
    Splat s;
    float radius;
    ok[l] = project_gaussian(view, gi, D, s, radius) ? 1 : 0;
    const TileRect rect = tile_rect(view, s, radius);
    f[0][l] = s.mean[0];
    f[1][l] = s.mean[1];
    f[2][l] = s.conic[0];
    f[3][l] = s.conic[1];
    f[4][l] = s.conic[2];
    f[5][l] = s.opacity;
    f[6][l] = s.color[0];
    f[7][l] = s.color[1];
    f[8][l] = s.color[2];
    f[9][l] = s.depth;
    r[0][l] = rect.x0;
    r[1][l] = rect.y0;
    r[2][l] = rect.x1;
    r[3][l] = rect.y1;
  }
  for (int l = 0; l < kLanes; ++l) {
    if (!ok[l]) {
      splats[i0 + l] = Splat{};
      rects[i0 + l] = TileRect{};
      continue;
    }
    splats[i0 + l] = Splat{{f[0][l], f[1][l]}, {f[2][l], f[3][l], f[4][l]}, f[5][l], {f[6][l], f[7][l], f[8][l]}, f[9][l]};
    rects[i0 + l] = TileRect{r[0][l], r[1][l], r[2][l], r[3][l]};
  }
}

// Full blocks of kLanes Gaussians in the vector loop; the last n % kLanes one at a time.
template <int D>
void project_lanes(const View& view, const GaussianViews& g, Span<Splat> splats, Span<TileRect> rects) {
  const int64_t n = g.means.size, blocks = n / kLanes;
  parallel_for(CpuBackend{}, blocks, [&](int64_t b) { project_block<D>(view, g, b * kLanes, splats.data, rects.data); });
  if (blocks * kLanes == n) return;
  // the last n % kLanes one at a time: the per-Gaussian loop over views of them
  const int64_t i0 = blocks * kLanes, m = n - i0, k = view.sh_stride;
  auto tail = [&](auto span, int64_t per) { return decltype(span){span.data + i0 * per, m * per}; };
  const GaussianViews gt{tail(g.means, 1), tail(g.log_scales, 1), tail(g.quats, 1), tail(g.logit_opacities, 1),
                         tail(g.sh, k), tail(g.plane_ids, 1)};
  project_splats(CpuBackend{}, view, gt, tail(splats, 1), tail(rects, 1));
}

// Gradients of Gaussians [i0, i0 + kLanes) side by side, as project_block: project_gaussian_bwd in
// a vector loop, its SH gradients added lane-major (LaneShGrad), then each lane stored as the
// per-Gaussian loop stores it. A block where no splat has a gradient (out of view) only clears
// `touched`.
template <int D>
void project_bwd_block(const View& view, const GaussianViews& g, const SplatGrad* v_splats, const GaussianGradViews& v,
                       int64_t i0) {
  bool live[kLanes];
  bool any = false;
  for (int l = 0; l < kLanes; ++l) {
    live[l] = !is_zero(v_splats[i0 + l]);
    any = any | live[l];
  }
  if (!any) {
    for (int l = 0; l < kLanes; ++l) v.touched[i0 + l] = 0;
    return;
  }
  constexpr int K = sh_count(D);
  alignas(32) float sh[3 * K * kLanes];
  const LaneInputs in = lane_inputs<D>(g, i0, view.sh_stride, sh);
  alignas(32) float vs[10][kLanes];  // the splat gradients, field by field (a 10-float record is no vector load)
  for (int l = 0; l < kLanes; ++l) {
    const SplatGrad& s = v_splats[i0 + l];
    const float fields[10] = {s.mean[0], s.mean[1], s.conic[0], s.conic[1], s.conic[2],
                              s.opacity, s.color[0], s.color[1], s.color[2], s.depth};
    for (int k = 0; k < 10; ++k) vs[k][l] = fields[k];
  }
  alignas(32) float v_sh[3 * K * kLanes] = {};
  alignas(32) float out[11][kLanes];
  alignas(32) int32_t ok[kLanes];
#pragma GCC ivdep
  for (int l = 0; l < kLanes; ++l) {
    const auto gi = RRG_LANE_GAUSSIAN(in, i0 + l, l);
    const SplatGrad s{{vs[0][l], vs[1][l]}, {vs[2][l], vs[3][l], vs[4][l]}, vs[5][l], {vs[6][l], vs[7][l], vs[8][l]}, vs[9][l]};
    Vec3<float> v_mean, v_log_scale;
    Vec4<float> v_quat;
    float v_logit;
    ok[l] = project_gaussian_bwd(view, gi, D, s, v_mean, v_log_scale, v_quat, v_logit, LaneShGrad<kLanes>{v_sh + l}) ? 1 : 0;
    for (int c = 0; c < 3; ++c) {
      out[c][l] = v_mean[c];
      out[3 + c][l] = v_log_scale[c];
    }
    for (int c = 0; c < 4; ++c) out[6 + c][l] = v_quat[c];
    out[10][l] = v_logit;
  }
  for (int l = 0; l < kLanes; ++l) {
    const int64_t i = i0 + l;
    if (!live[l]) {
      v.touched[i] = 0;
      continue;
    }
    Vec3<float> rows[kMaxShCoeffs];
    for (int k = 0; k < kMaxShCoeffs; ++k) rows[k].setZero();
    if (!ok[l]) {  // culled (never the case for a splat that drew a pixel): no gradient
      store_gaussian_grad(v, i, view.sh_stride, Vec3<float>::Zero(), Vec3<float>::Zero(), Vec4<float>::Zero(), 0.0f, rows);
      continue;
    }
    for (int k = 0; k < K; ++k)
      for (int c = 0; c < 3; ++c) rows[k][c] = v_sh[(3 * k + c) * kLanes + l];
    store_gaussian_grad(v, i, view.sh_stride, Vec3<float>(out[0][l], out[1][l], out[2][l]),
                        Vec3<float>(out[3][l], out[4][l], out[5][l]),
                        Vec4<float>(out[6][l], out[7][l], out[8][l], out[9][l]), out[10][l], rows);
  }
}

template <int D>
void project_bwd_lanes(const View& view, const GaussianViews& g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  const int64_t n = g.means.size, blocks = n / kLanes;
  parallel_for(CpuBackend{}, blocks, [&](int64_t b) { project_bwd_block<D>(view, g, v_splats.data, v, b * kLanes); });
  if (blocks * kLanes == n) return;
  // the last n % kLanes one at a time: the per-Gaussian loop over views of them
  const int64_t i0 = blocks * kLanes, m = n - i0, k = view.sh_stride;
  auto tail = [&](auto span, int64_t per) { return decltype(span){span.data + i0 * per, m * per}; };
  const GaussianViews gt{tail(g.means, 1), tail(g.log_scales, 1), tail(g.quats, 1), tail(g.logit_opacities, 1),
                         tail(g.sh, k), tail(g.plane_ids, 1)};
  const GaussianGradViews vt{tail(v.v_means, 1), tail(v.v_log_scales, 1), tail(v.v_quats, 1),
                             tail(v.v_logit_opacities, 1), tail(v.v_sh, k), tail(v.touched, 1)};
  project_bwd(CpuBackend{}, view, gt, tail(v_splats, 1), vt);
}

}  // namespace

void project_splats_cpu(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects) {
  switch (view.sh_degree) {
    case 0: return project_lanes<0>(view, g, splats, rects);
    case 1: return project_lanes<1>(view, g, splats, rects);
    case 2: return project_lanes<2>(view, g, splats, rects);
    case 3: return project_lanes<3>(view, g, splats, rects);
    default: return project_splats(CpuBackend{}, view, g, splats, rects);
  }
}

void project_splats_per_gaussian_cpu(View view, GaussianViews g, Span<Splat> splats, Span<TileRect> rects) {
  project_splats(CpuBackend{}, view, g, splats, rects);
}

void count_tiles_cpu(Span<const TileRect> rects, Span<const int32_t> plane_ids, int32_t plane,
                     Span<int32_t> counts) {
  count_tiles(CpuBackend{}, rects, plane_ids, plane, counts);
}

void write_keys_cpu(int tiles_x, Span<const TileRect> rects, Span<const Splat> splats,
                    Span<const int32_t> counts, Span<const int32_t> offsets, bool with_depth,
                    Span<uint64_t> keys, Span<int32_t> values) {
  write_keys(CpuBackend{}, tiles_x, rects, splats, counts, offsets, with_depth, keys, values);
}

void tile_ranges_cpu(Span<const uint64_t> keys, bool with_depth, Span<TileRange> ranges) {
  tile_ranges(CpuBackend{}, keys, with_depth, ranges);
}

void project_bwd_cpu(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  switch (view.sh_degree) {
    case 0: return project_bwd_lanes<0>(view, g, v_splats, v);
    case 1: return project_bwd_lanes<1>(view, g, v_splats, v);
    case 2: return project_bwd_lanes<2>(view, g, v_splats, v);
    case 3: return project_bwd_lanes<3>(view, g, v_splats, v);
    default: return project_bwd(CpuBackend{}, view, g, v_splats, v);
  }
}

void project_bwd_per_gaussian_cpu(View view, GaussianViews g, Span<const SplatGrad> v_splats, GaussianGradViews v) {
  project_bwd(CpuBackend{}, view, g, v_splats, v);
}

}  // namespace rrg::kernel
#undef RRG_LANE_GAUSSIAN
