#pragma once
// Per-pixel loops of pass 2 and pass 3 (forward and backward) and the composite, templated on the
// back end. rasterize_cuda.cu instantiates all of them; the CPU back end (rasterize_cpu.cpp) runs
// the same per-pixel maths tile by tile, splat-major, and takes only the composite and the group
// mask from here (the tests run these loops on the CPU as its reference). Pixels run in tile-major
// order (blend_device.h: tile_pixel) so neighbouring work items walk the same tile list.
#include "core/common/atomics.h"
#include "core/common/parallel_for.h"
#include "core/render/blend_device.h"
#include "core/render/rasterize_cpu_scratch.h"
#include "core/render/splat_grad_ops.h"
#include "core/render/stage_args.h"

namespace rrg::kernel {

inline int64_t tile_slots(const View& v) { return int64_t(v.tiles_x()) * v.tiles_y() * kTileSize * kTileSize; }

}  // namespace rrg::kernel

namespace rrg {
// Adds a pixel's splat gradient into the shared one. CPU: plain atomics, for the per-pixel loops
// below that the tests run on the CPU as the reference (the CPU back end's tile schedule sums the
// tiles' entries in a fixed order instead, rasterize_cpu.cpp). The CUDA overload (grad_accumulate.cuh) first sums the lanes of a warp that hold the
// same Gaussian, then does one atomic per field. Found by argument-dependent lookup on the tag.
RRG_HD inline void accumulate_grad(CpuBackend, kernel::SplatGrad* dst, const kernel::SplatGrad& g) {
  kernel::atomic_add_grad(dst, g);
}
}  // namespace rrg

namespace rrg::kernel {

template <class Backend>
void base_fwd(Backend b, BaseFwdArgs a) {
  parallel_for(b, tile_slots(a.view), [=] RRG_HD(int64_t i) {
    int x, y, tile;
    if (!tile_pixel(i, a.view.width, a.view.height, a.view.tiles_x(), x, y, tile)) return;
    const float px = float(x), py = float(y), D_t = a.D_t(x, y);
    BaseAccumT<float> acc;
    const TileRange r = a.bins.ranges[tile];
    for (int32_t k = r.begin; k < r.end; ++k) base_accumulate(acc, a.splats[a.bins.values[k]], px, py, D_t, a.eps);
    Vec3<float> C_b;
    float D_b;
    base_resolve(acc, Vec3<float>(a.C_t(x, y)), D_t, C_b, D_b);
    a.C_g(x, y) = acc.C_g;
    a.W_g(x, y) = acc.W_g;
    a.D_g(x, y) = acc.D_g;
    a.C_b(x, y) = C_b;
    a.D_b(x, y) = D_b;
  });
}

template <class Backend>
void base_bwd(Backend b, BaseBwdArgs a) {
  parallel_for(b, tile_slots(a.view), [=] RRG_HD(int64_t i) {
    int x, y, tile;
    if (!tile_pixel(i, a.view.width, a.view.height, a.view.tiles_x(), x, y, tile)) return;
    const Vec3<float> v_C_b = a.v_C_b(x, y);
    const float v_D_b = a.v_D_b(x, y);
    if (exactly_zero(v_C_b) && v_D_b == 0.0f) return;
    const float px = float(x), py = float(y), D_t = a.D_t(x, y);
    const auto up = base_resolve_bwd(a.W_g(x, y), D_t, Vec3<float>(a.C_b(x, y)), a.D_b(x, y), v_C_b, v_D_b);
    const TileRange r = a.bins.ranges[tile];
    for (int32_t k = r.begin; k < r.end; ++k) {
      const int32_t g = a.bins.values[k];
      SplatGrad v{};
      base_splat_bwd(a.splats[g], px, py, D_t, a.eps, up, v);
      accumulate_grad(b, &a.v_splats[g], v);
    }
  });
}

// Whether pass 3 considers pixel (x, y) at all, and its plane id.
RRG_HD inline bool refl_pixel_active(PlaneMode mode, int32_t plane, int32_t I) {
  if (mode == PlaneMode::Match) return I != 0;
  if (mode == PlaneMode::PixelOnly) return I == plane;
  return true;
}

template <class Backend>
void refl_fwd(Backend b, ReflFwdArgs a) {
  parallel_for(b, tile_slots(a.view), [=] RRG_HD(int64_t i) {
    int x, y, tile;
    if (!tile_pixel(i, a.view.width, a.view.height, a.view.tiles_x(), x, y, tile)) return;
    const int32_t I = a.I(x, y);
    ReflStateT<float> st;
    if (refl_pixel_active(a.mode, a.plane, I)) {
      const float px = float(x), py = float(y);
      const TileRange r = a.bins.ranges[tile];
      for (int32_t k = r.begin; k < r.end; ++k) {
        const int32_t g = a.bins.values[k];
        if (a.mode == PlaneMode::Match && a.plane_ids[g] != I) continue;  // 1(l_i == I(u))
        if (!refl_step(st, a.splats[g], px, py)) break;                   // early termination
        if (refl_mean_above(st, a.stop_mean)) break;                       // decided (stop_mean)
      }
    }
    a.C_r(x, y) = st.C;
    a.W_r(x, y) = st.W;
  });
}

template <class Backend>
void refl_bwd(Backend b, ReflBwdArgs a) {
  parallel_for(b, tile_slots(a.view), [=] RRG_HD(int64_t i) {
    int x, y, tile;
    if (!tile_pixel(i, a.view.width, a.view.height, a.view.tiles_x(), x, y, tile)) return;
    const int32_t I = a.I(x, y);
    if (!refl_pixel_active(a.mode, a.plane, I)) return;
    const Vec3<float> v_C = a.v_C_r(x, y);
    if (exactly_zero(v_C)) return;
    const Vec3<float> C_final = a.C_r(x, y);
    const float W_final = a.W_r(x, y);
    const float px = float(x), py = float(y);
    ReflStateT<float> st;
    const TileRange r = a.bins.ranges[tile];
    for (int32_t k = r.begin; k < r.end; ++k) {
      const int32_t g = a.bins.values[k];
      if (a.mode == PlaneMode::Match && a.plane_ids[g] != I) continue;
      SplatGrad v{};
      const bool more = refl_step_bwd(st, a.splats[g], px, py, C_final, W_final, v_C, 0.0f, v);
      if (!more) break;
      accumulate_grad(b, &a.v_splats[g], v);
    }
  });
}

// C = C_b + R C_r
template <class Backend>
void composite(Backend b, ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R,
               ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C) {
  parallel_for(b, C.size(), [=] RRG_HD(int64_t i) { C[i] = C_b[i] + R[i] * C_r[i]; });
}

// Upstream of C_r: R v_C (+ v_C_r when given).
template <class Backend>
void composite_bwd(Backend b, ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R,
                   ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra, ImageView<Eigen::Vector3f> v_C_r) {
  parallel_for(b, v_C.size(), [=] RRG_HD(int64_t i) {
    Eigen::Vector3f v = R[i] * v_C[i];
    if (has_extra) v += v_C_r_extra[i];
    v_C_r[i] = v;
  });
}

// Multi-pass composite: where I(u) == plane, C_r(u) = C_r^plane(u), W_r likewise.
template <class Backend>
void mask_group(Backend b, ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k,
                ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r) {
  parallel_for(b, I.size(), [=] RRG_HD(int64_t i) {
    if (I[i] != plane) return;
    C_r[i] = C_k[i];
    W_r[i] = W_k[i];
  });
}

// The CPU passes keep their scratch in a CpuRasterScratch (rasterize_cpu_scratch.h): a backward pass
// reads what the forward of the same pass stored in it for the same render (the splats' reach, and
// for pass 2 the falloffs; same splats, bins and D_t; std::logic_error when it holds no such
// forward), and both backward passes sum each splat's gradient from per-entry sums in entry order,
// whatever the number of threads.
void base_fwd_cpu(BaseFwdArgs a, CpuRasterScratch& scratch);
void base_fwd_cuda(BaseFwdArgs a);
void base_bwd_cpu(BaseBwdArgs a, CpuRasterScratch& scratch);
void base_bwd_cuda(BaseBwdArgs a);
void refl_fwd_cpu(ReflFwdArgs a, CpuRasterScratch& scratch);
void refl_fwd_cuda(ReflFwdArgs a);
void refl_bwd_cpu(ReflBwdArgs a, CpuRasterScratch& scratch);
void refl_bwd_cuda(ReflBwdArgs a);
void composite_cpu(ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R, ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C);
void composite_cuda(ImageView<const Eigen::Vector3f> C_b, ImageView<const float> R, ImageView<const Eigen::Vector3f> C_r, ImageView<Eigen::Vector3f> C);
void composite_bwd_cpu(ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R, ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra, ImageView<Eigen::Vector3f> v_C_r);
void composite_bwd_cuda(ImageView<const Eigen::Vector3f> v_C, ImageView<const float> R, ImageView<const Eigen::Vector3f> v_C_r_extra, bool has_extra, ImageView<Eigen::Vector3f> v_C_r);
void mask_group_cpu(ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k, ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r);
void mask_group_cuda(ImageView<const int32_t> I, int32_t plane, ImageView<const Eigen::Vector3f> C_k, ImageView<const float> W_k, ImageView<Eigen::Vector3f> C_r, ImageView<float> W_r);

}  // namespace rrg::kernel
