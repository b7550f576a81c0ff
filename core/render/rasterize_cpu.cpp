// The CPU back end of the rasterisation passes. The per-pixel maths is blend_device.h's, as on
// CUDA; only the schedule differs. CUDA runs one thread per pixel over the tile's splat list and
// reduces gradients across a warp (rasterize_impl.h, grad_accumulate.cuh). A CPU thread instead
// takes a whole 16 x 16 tile and walks the tile's splats in list order, visiting for each splat only
// the pixels of the tile it can reach (splat_pixel_bounds). Every pixel therefore sees the same
// splats in the same order as in the per-pixel loop (forward results are the same), pixels a splat
// cannot reach cost nothing, and a splat's gradient is summed over the tile locally, once per
// (tile, splat) entry instead of once per (pixel, splat). The backward then adds the entries into
// the splats in entry order (sum_entries), not with atomics in whatever order threads finish their
// tiles: the gradients, and so the maps of `--sync` runs, are the same bit for bit whatever the
// number of threads. Pass 2's forward keeps the falloff of every pair it visits (CpuRasterScratch),
// and its backward reads them instead of evaluating the exponential again. Pass 2's forward also
// evaluates a splat on eight pixels of a row at once (a vectorised lane loop over the same
// blend_device.h functions, written without branches for that); its images are the per-pixel
// loop's bit for bit. (The backward stays scalar: in lanes it was no faster, twice; its time goes to
// fetching the scattered splat records, not to arithmetic. bench/RESULTS.md, fifteenth session.)
#include "core/common/parallel_for.h"
#include "core/render/rasterize_impl.h"

#include <omp.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace rrg::kernel {

namespace {

constexpr int kTilePixels = kTileSize * kTileSize;

// A tile's pixels [x0, x1) x [y0, y1), clipped to the image; pixel (x, y) is at local index
// (y - y0) * kTileSize + (x - x0).
struct TilePixels : PixelRect {
  int local(int x, int y) const { return (y - y0) * kTileSize + (x - x0); }
};

TilePixels tile_pixels(const View& v, int tile) {
  const int x0 = (tile % v.tiles_x()) * kTileSize, y0 = (tile / v.tiles_x()) * kTileSize;
  return {{x0, y0, std::min(x0 + kTileSize, v.width), std::min(y0 + kTileSize, v.height)}};
}

// Pass 2 evaluates a splat on up to kLanes consecutive pixels of a row at once (an AVX2 register of
// floats; the splats of a trained map reach about five pixels across), from per-tile arrays of
// fields (structure of arrays) whose rows are padded so that kLanes lanes from any column stay
// inside. Lanes past the splat's reach add nothing.
constexpr int kLanes = 8;

template <int Fields>
struct LaneTile {
  static constexpr int kStride = kTileSize + kLanes;
  alignas(32) float v[Fields][kTileSize * kStride] = {};
  static int index(const TilePixels& t, int x, int y) { return (y - t.y0) * kStride + (x - t.x0); }
  float* field(int f) { return v[f]; }
  float& at(int f, const TilePixels& t, int x, int y) { return v[f][index(t, x, y)]; }
};

// Every splat's reachable pixels [x0, x1) x [y0, y1) (splat_pixel_bounds), computed once per pass
// rather than once per (tile, splat) entry; empty (x0 = x1) when it reaches none.
void splat_reach(Span<const Splat> splats, std::vector<PixelRect>& out) {
  out.resize(size_t(splats.size));
#pragma omp parallel for schedule(static)
  for (int64_t g = 0; g < splats.size; ++g) {
    int x0, y0, x1, y1;
    out[size_t(g)] = splat_pixel_bounds(splats[g], x0, y0, x1, y1) ? PixelRect{x0, y0, x1 + 1, y1 + 1}
                                                                    : PixelRect{0, 0, 0, 0};
  }
}

// The pixels of tile t within a splat's reach; false when none.
bool reach(const PixelRect& splat, const TilePixels& t, PixelRect& out) {
  out = {std::max(splat.x0, t.x0), std::max(splat.y0, t.y0), std::min(splat.x1, t.x1), std::min(splat.y1, t.y1)};
  return out.x0 < out.x1 && out.y0 < out.y1;
}

// A tile's list names its splats in depth order, scattered over the splat arrays (megabytes for a
// trained map): the loops over a list request the records of the entry kPrefetchAhead places on,
// so that their cache misses overlap the work on the entries before it.
constexpr int kPrefetchAhead = 8;

template <class T>
void prefetch_record(const T* p) {
  RRG_PREFETCH(p);
  RRG_PREFETCH(reinterpret_cast<const char*>(p) + sizeof(T) - 1);  // a record may straddle two lines
}

// f(k, g, splat, pixels) for every entry k of the tile's list, in list order, whose splat g reaches
// the tile; pixels is the part of the tile within its reach. Stops early when more() turns false.
template <class More, class F>
void for_each_reaching_splat(const BinViews& bins, Span<const Splat> splats, const std::vector<PixelRect>& bounds,
                             int tile, const TilePixels& tp, More more, F f) {
  const TileRange r = bins.ranges[tile];
  for (int32_t k = r.begin; k < r.end && more(); ++k) {
    if (k + kPrefetchAhead < r.end) {
      const int32_t ahead = bins.values[k + kPrefetchAhead];
      prefetch_record(&bounds[size_t(ahead)]);
      prefetch_record(&splats[ahead]);
    }
    const int32_t g = bins.values[k];
    PixelRect p;
    if (reach(bounds[size_t(g)], tp, p)) f(k, g, splats[g], p);
  }
}

// The tile's entries set to zero: an entry whose splat misses the tile, or that an early stop never
// reaches, holds no gradient (the scratch keeps an earlier pass's values otherwise).
void clear_entries(const BinViews& bins, int tile, std::vector<SplatGrad>& entries) {
  const TileRange r = bins.ranges[tile];
  if (r.end > r.begin) std::memset(&entries[size_t(r.begin)], 0, size_t(r.end - r.begin) * sizeof(SplatGrad));
}

// Pass 2's pairs: per tile the (entry, pixel) pairs its forward visits, as offsets into G; G is
// sized for them when they are at most s.max_kept_pairs, and left empty (falloffs not kept, the
// backward evaluates them again) above, so that the scratch stays within 4 · max_kept_pairs bytes.
void base_pairs(const View& v, const BinViews& bins, CpuRasterScratch& s) {
  const int tiles = v.tiles_x() * v.tiles_y();
  s.pair_offset.assign(size_t(tiles) + 1, 0);
#pragma omp parallel for schedule(dynamic, 4)
  for (int t = 0; t < tiles; ++t) {
    const TilePixels tp = tile_pixels(v, t);
    const TileRange r = bins.ranges[t];
    int64_t n = 0;
    for (int32_t k = r.begin; k < r.end; ++k) {
      if (k + kPrefetchAhead < r.end) prefetch_record(&s.reach[size_t(bins.values[k + kPrefetchAhead])]);
      PixelRect p;
      if (reach(s.reach[size_t(bins.values[k])], tp, p)) n += int64_t(p.x1 - p.x0) * (p.y1 - p.y0);
    }
    s.pair_offset[size_t(t) + 1] = n;
  }
  for (int t = 0; t < tiles; ++t) s.pair_offset[size_t(t) + 1] += s.pair_offset[size_t(t)];
  if (s.pair_offset.back() <= s.max_kept_pairs) {
    s.G.resize(size_t(s.pair_offset.back()));
  } else {
    s.G.clear();
    s.G.shrink_to_fit();
  }
}

// v_splats[g] += the entries k of splat g (values[k] == g), in increasing k. Each thread owns a
// contiguous range of splats and scans every entry, so each splat's sum has one order whatever the
// number of threads.
void sum_entries(const BinViews& bins, const std::vector<SplatGrad>& entries, Span<SplatGrad> v_splats) {
  const int64_t n = v_splats.size, m = bins.values.size;
  constexpr int kFields = int(sizeof(SplatGrad) / sizeof(float));
#pragma omp parallel
  {
    const int64_t parts = omp_get_num_threads(), part = omp_get_thread_num();
    const int64_t g0 = n * part / parts, g1 = n * (part + 1) / parts;
    for (int64_t k = 0; k < m; ++k) {
      const int32_t g = bins.values[k];
      if (g < g0 || g >= g1 || is_zero(entries[size_t(k)])) continue;
      float* d = &v_splats[g].mean[0];
      const float* e = &entries[size_t(k)].mean[0];
      for (int f = 0; f < kFields; ++f) d[f] += e[f];
    }
  }
}

// f(tile) for every tile on OpenMP threads; tiles differ in work, so they are handed out one by one.
template <class F>
void for_each_tile(const View& v, F f) {
  const int tiles = v.tiles_x() * v.tiles_y();
#pragma omp parallel for schedule(dynamic, 1)
  for (int t = 0; t < tiles; ++t) f(t);
}

}  // namespace

void base_fwd_cpu(BaseFwdArgs a, CpuRasterScratch& scratch) {
  splat_reach(a.splats, scratch.reach);
  base_pairs(a.view, a.bins, scratch);
  for_each_tile(a.view, [&](int tile) {
    const TilePixels tp = tile_pixels(a.view, tile);
    LaneTile<5> acc;  // A_b[c] (3), A_b[1], A_b[d]
    LaneTile<1> D_t;
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) D_t.at(0, tp, x, y) = a.D_t(x, y);
    const bool keep = !scratch.G.empty();
    float* G = keep ? scratch.G.data() + scratch.pair_offset[size_t(tile)] : nullptr;  // this tile's pairs
    const auto splat_fwd = [&](int32_t, int32_t, const Splat& splat, const PixelRect& p) {
      const Splat s = splat;  // local copies: the lane loop reads no memory through references
      const float eps = a.eps;
      for (int y = p.y0; y < p.y1; ++y)
        for (int x0 = p.x0; x0 < p.x1; x0 += kLanes) {
          const int n = std::min(kLanes, p.x1 - x0);
          const int l0 = LaneTile<1>::index(tp, x0, y);
          float* __restrict C0 = acc.field(0) + l0;
          float* __restrict C1 = acc.field(1) + l0;
          float* __restrict C2 = acc.field(2) + l0;
          float* __restrict W = acc.field(3) + l0;
          float* __restrict D = acc.field(4) + l0;
          const float* __restrict Dt = D_t.field(0) + l0;
          float g[kLanes];
#pragma omp simd
          for (int i = 0; i < kLanes; ++i) {
            const float G_i = base_falloff_G(s, s.mean[0] - float(x0 + i), s.mean[1] - float(y), Dt[i], eps);
            const float alpha = i < n ? base_alpha(s, G_i) : 0.0f;
            g[i] = alpha != 0.0f ? G_i : 0.0f;
            float c0 = C0[i], c1 = C1[i], c2 = C2[i], w = W[i], d = D[i];
            base_add(c0, c1, c2, w, d, s, alpha);  // kept only where alpha != 0, as in the per-pixel loop
            const bool add = alpha != 0.0f;
            C0[i] = add ? c0 : C0[i], C1[i] = add ? c1 : C1[i], C2[i] = add ? c2 : C2[i];
            W[i] = add ? w : W[i], D[i] = add ? d : D[i];
          }
          if (keep) {
            std::memcpy(G, g, size_t(n) * sizeof(float));
            G += n;
          }
        }
    };
    for_each_reaching_splat(a.bins, a.splats, scratch.reach, tile, tp, [] { return true; }, splat_fwd);
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) {
        BaseAccumT<float> ac;
        ac.C_g = Vec3<float>(acc.at(0, tp, x, y), acc.at(1, tp, x, y), acc.at(2, tp, x, y));
        ac.W_g = acc.at(3, tp, x, y);
        ac.D_g = acc.at(4, tp, x, y);
        Vec3<float> C_b;
        float D_b;
        base_resolve(ac, Vec3<float>(a.C_t(x, y)), D_t.at(0, tp, x, y), C_b, D_b);
        a.C_g(x, y) = ac.C_g;
        a.W_g(x, y) = ac.W_g;
        a.D_g(x, y) = ac.D_g;
        a.C_b(x, y) = C_b;
        a.D_b(x, y) = D_b;
      }
  });
}

void base_bwd_cpu(BaseBwdArgs a, CpuRasterScratch& scratch) {
  const int tiles = a.view.tiles_x() * a.view.tiles_y();
  if (scratch.reach.size() != size_t(a.splats.size) || scratch.pair_offset.size() != size_t(tiles) + 1 ||
      (scratch.G.size() != size_t(scratch.pair_offset.back()) && scratch.pair_offset.back() <= scratch.max_kept_pairs))
    throw std::logic_error("base_bwd_cpu: the scratch does not hold this render's forward pass");
  const bool kept = scratch.pair_offset.back() <= scratch.max_kept_pairs;
  std::vector<SplatGrad>& entries = scratch.entries;
  entries.resize(size_t(a.bins.values.size));
  for_each_tile(a.view, [&](int tile) {
    clear_entries(a.bins, tile, entries);
    const TilePixels tp = tile_pixels(a.view, tile);
    BaseUpstreamT<float> up[kTilePixels];
    float D_t[kTilePixels];
    bool active[kTilePixels] = {};
    bool any = false;
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) {
        const int l = tp.local(x, y);
        const Vec3<float> v_C_b = a.v_C_b(x, y);
        const float v_D_b = a.v_D_b(x, y);
        if (exactly_zero(v_C_b) && v_D_b == 0.0f) continue;
        active[l] = any = true;
        D_t[l] = a.D_t(x, y);
        up[l] = base_resolve_bwd(a.W_g(x, y), D_t[l], Vec3<float>(a.C_b(x, y)), a.D_b(x, y), v_C_b, v_D_b);
      }
    if (!any) return;
    // The forward's falloffs of this tile's pairs, in the same visiting order: alpha and the
    // gradient from them are those base_splat_bwd would compute, bit for bit.
    const float* G = kept ? scratch.G.data() + scratch.pair_offset[size_t(tile)] : nullptr;
    const auto splat_bwd = [&](int32_t k, int32_t, const Splat& s, const PixelRect& p) {
      SplatGrad v{};
      for (int y = p.y0; y < p.y1; ++y)
        for (int x = p.x0; x < p.x1; ++x) {
          const int l = tp.local(x, y);
          if (!kept) {
            if (active[l]) base_splat_bwd(s, float(x), float(y), D_t[l], a.eps, up[l], v);
            continue;
          }
          const float g = *G++;
          if (g == 0.0f || !active[l]) continue;
          const SplatFalloffT<float> f{s.mean[0] - float(x), s.mean[1] - float(y), g, true};
          base_splat_bwd(s, f, splat_alpha(s, f, 1.0f), up[l], v);
        }
      entries[size_t(k)] = v;
    };
    for_each_reaching_splat(a.bins, a.splats, scratch.reach, tile, tp, [] { return true; }, splat_bwd);
  });
  sum_entries(a.bins, entries, a.v_splats);
}

void refl_fwd_cpu(ReflFwdArgs a, CpuRasterScratch& scratch) {
  splat_reach(a.splats, scratch.reach);
  for_each_tile(a.view, [&](int tile) {
    const TilePixels tp = tile_pixels(a.view, tile);
    ReflStateT<float> st[kTilePixels];
    int32_t I[kTilePixels];
    bool alive[kTilePixels] = {};
    int live = 0;
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) {
        const int l = tp.local(x, y);
        I[l] = a.I(x, y);
        alive[l] = refl_pixel_active(a.mode, a.plane, I[l]);
        live += alive[l] ? 1 : 0;
      }
    // The mean test only where it can stop a pixel (the tracking mask's threshold; the mapper's
    // renders pass +inf): a visit's cost is a few dozen flops, and the test on the colour just
    // composited sat on its critical path. NaN never stops, as in refl_mean_above.
    const auto composite = [&](auto can_stop) {
      const auto splat_fwd = [&](int32_t, int32_t g, const Splat& s, const PixelRect& p) {
        for (int y = p.y0; y < p.y1; ++y)
          for (int x = p.x0; x < p.x1; ++x) {
            const int l = tp.local(x, y);
            if (!alive[l] || (a.mode == PlaneMode::Match && a.plane_ids[g] != I[l])) continue;  // 1(l_i == I(u))
            bool done = !refl_step(st[l], s, float(x), float(y));  // early termination
            if constexpr (decltype(can_stop)::value) done = done || refl_mean_above(st[l], a.stop_mean);
            if (done) alive[l] = false, --live;
          }
      };
      for_each_reaching_splat(a.bins, a.splats, scratch.reach, tile, tp, [&] { return live > 0; }, splat_fwd);
    };
    if (a.stop_mean < std::numeric_limits<float>::infinity()) composite(std::true_type{});
    else composite(std::false_type{});
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) {
        const int l = tp.local(x, y);
        a.C_r(x, y) = st[l].C;
        a.W_r(x, y) = st[l].W;
      }
  });
}

void refl_bwd_cpu(ReflBwdArgs a, CpuRasterScratch& scratch) {
  if (scratch.reach.size() != size_t(a.splats.size))  // the forward's reach of the same splats
    throw std::logic_error("refl_bwd_cpu: the scratch does not hold this render's forward pass");
  std::vector<SplatGrad>& entries = scratch.entries;
  entries.resize(size_t(a.bins.values.size));
  for_each_tile(a.view, [&](int tile) {
    clear_entries(a.bins, tile, entries);
    const TilePixels tp = tile_pixels(a.view, tile);
    ReflStateT<float> st[kTilePixels];
    Vec3<float> v_C[kTilePixels], C_final[kTilePixels];
    float W_final[kTilePixels];
    int32_t I[kTilePixels];
    bool alive[kTilePixels] = {};
    int live = 0;
    for (int y = tp.y0; y < tp.y1; ++y)
      for (int x = tp.x0; x < tp.x1; ++x) {
        const int l = tp.local(x, y);
        I[l] = a.I(x, y);
        if (!refl_pixel_active(a.mode, a.plane, I[l])) continue;
        v_C[l] = a.v_C_r(x, y);
        if (exactly_zero(v_C[l])) continue;
        C_final[l] = a.C_r(x, y);
        W_final[l] = a.W_r(x, y);
        alive[l] = true;
        ++live;
      }
    const auto splat_bwd = [&](int32_t k, int32_t g, const Splat& s, const PixelRect& p) {
      SplatGrad v{};
      for (int y = p.y0; y < p.y1; ++y)
        for (int x = p.x0; x < p.x1; ++x) {
          const int l = tp.local(x, y);
          if (!alive[l] || (a.mode == PlaneMode::Match && a.plane_ids[g] != I[l])) continue;
          if (!refl_step_bwd(st[l], s, float(x), float(y), C_final[l], W_final[l], v_C[l], 0.0f, v))
            alive[l] = false, --live;
        }
      entries[size_t(k)] = v;
    };
    for_each_reaching_splat(a.bins, a.splats, scratch.reach, tile, tp, [&] { return live > 0; }, splat_bwd);
  });
  sum_entries(a.bins, entries, a.v_splats);
}

void composite_cpu(ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R,
                   ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C) {
  composite(CpuBackend{}, C_b, R, C_r, C);
}

void composite_bwd_cpu(ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R,
                       ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra,
                       ImageView<Eigen::Vector3f> v_C_r) {
  composite_bwd(CpuBackend{}, v_C, R, v_C_r_extra, has_extra, v_C_r);
}

void mask_group_cpu(ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k,
                    ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r) {
  mask_group(CpuBackend{}, I, plane, C_k, W_k, C_r, W_r);
}

}  // namespace rrg::kernel
