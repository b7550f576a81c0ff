// The CPU back end runs passes 2 and 3 tile by tile, splat-major, visiting only the pixels a splat
// can reach (rasterize_cpu.cpp); CUDA runs them pixel by pixel (rasterize_impl.h). These tests run
// the per-pixel template on the CPU as the reference and require the same images and gradients,
// on splats chosen to stress the reach bound: thin and rotated ellipses, huge ones, opacities around
// the 1/255 cut, splats centred off the image and off their tiles. The CPU backward's gradients
// must also not depend on the number of threads (it sums the tiles' entries in a fixed order).
#include "core/common/parallel_for.h"
#include "core/render/rasterize_impl.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

namespace rrg::kernel {
namespace {

struct Scene {
  int w = 70, h = 45;  // partial tiles on the right and bottom
  View view{};
  std::vector<Splat> splats;
  std::vector<int32_t> plane_ids;
  std::vector<int32_t> values;
  std::vector<TileRange> ranges;
  std::vector<Eigen::Vector3f> C_t, v_C, C_r_in;
  std::vector<float> D_t, v_D;
  std::vector<int32_t> I;
};

Splat random_splat(std::mt19937& rng, int w, int h) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Splat s{};
  s.mean[0] = -10.0f + u(rng) * float(w + 20);
  s.mean[1] = -10.0f + u(rng) * float(h + 20);
  // Sigma' = R diag(l1, l2) R^T with l in [0.05, 40] px^2 (a few huge), then the conic is its inverse.
  const float th = u(rng) * 6.2831853f;
  float l1 = 0.05f + u(rng) * 12.0f, l2 = 0.05f + u(rng) * u(rng) * 40.0f;
  if (u(rng) < 0.05f) l1 = 400.0f;  // reaches across tiles
  const float c = std::cos(th), sn = std::sin(th);
  const float sxx = c * c * l1 + sn * sn * l2, syy = sn * sn * l1 + c * c * l2, sxy = c * sn * (l1 - l2);
  const float det = sxx * syy - sxy * sxy;
  s.conic[0] = syy / det;
  s.conic[1] = -sxy / det;
  s.conic[2] = sxx / det;
  const float pick = u(rng);
  s.opacity = pick < 0.1f ? kAlphaMin * (0.5f + u(rng)) : (pick < 0.2f ? 1.0f : u(rng));
  for (float& ch : s.color) ch = u(rng);
  s.depth = 0.5f + 3.0f * u(rng);
  return s;
}

Scene make_scene(uint32_t seed, int n) {
  Scene sc;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  sc.view.width = sc.w;
  sc.view.height = sc.h;
  for (int i = 0; i < n; ++i) {
    sc.splats.push_back(random_splat(rng, sc.w, sc.h));
    sc.plane_ids.push_back(int32_t(rng() % 3));
  }
  // Every tile lists every splat, in a per-tile shuffled order: lists longer than any binning
  // would make, and splats far from the tile (nothing may reach there).
  const int tiles = sc.view.tiles_x() * sc.view.tiles_y();
  for (int t = 0; t < tiles; ++t) {
    std::vector<int32_t> order(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) order[size_t(i)] = i;
    std::shuffle(order.begin(), order.end(), rng);
    sc.ranges.push_back({int32_t(sc.values.size()), int32_t(sc.values.size() + order.size())});
    sc.values.insert(sc.values.end(), order.begin(), order.end());
  }
  const size_t px = size_t(sc.w) * size_t(sc.h);
  for (size_t i = 0; i < px; ++i) {
    sc.C_t.emplace_back(u(rng), u(rng), u(rng));
    sc.D_t.push_back(u(rng) < 0.15f ? 0.0f : 0.5f + 3.0f * u(rng));  // some raycast misses
    sc.v_C.emplace_back(u(rng) < 0.1f ? Eigen::Vector3f::Zero() : Eigen::Vector3f(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
    sc.v_D.push_back(u(rng) < 0.5f ? 0.0f : u(rng) - 0.5f);
    sc.I.push_back(int32_t(rng() % 3));
  }
  return sc;
}

template <class T>
ImageView<T> img(std::vector<T>& v, const Scene& sc) {
  return {v.data(), sc.w, sc.h};
}
template <class T>
ImageView<const T> cimg(const std::vector<T>& v, const Scene& sc) {
  return {v.data(), sc.w, sc.h};
}
template <class T>
Span<const T> cspan(const std::vector<T>& v) {
  return {v.data(), int64_t(v.size())};
}

// A CPU scratch for a scene whose backward entries and pass-2 falloffs hold NaN: every value a
// pass reads must be one it (or, for the falloffs, the forward of the same render) wrote.
CpuRasterScratch poisoned_scratch(const Scene& sc) {
  CpuRasterScratch s;
  SplatGrad nan{};
  float* f = &nan.mean[0];
  for (int k = 0; k < int(sizeof(SplatGrad) / sizeof(float)); ++k) f[k] = std::nanf("");
  s.entries.assign(sc.values.size(), nan);
  s.G.assign(sc.values.size() * 8, std::nanf(""));
  return s;
}

struct BaseOut {
  std::vector<Eigen::Vector3f> C_g, C_b;
  std::vector<float> W_g, D_g, D_b;
  explicit BaseOut(size_t n) : C_g(n), C_b(n), W_g(n), D_g(n), D_b(n) {}
};

BaseFwdArgs base_fwd_args(Scene& sc, BaseOut& o) {
  BaseFwdArgs a{};
  a.view = sc.view;
  a.eps = 0.05f;
  a.splats = cspan(sc.splats);
  a.bins = {cspan(sc.values), cspan(sc.ranges)};
  a.C_t = cimg(sc.C_t, sc);
  a.D_t = cimg(sc.D_t, sc);
  a.C_g = img(o.C_g, sc);
  a.C_b = img(o.C_b, sc);
  a.W_g = img(o.W_g, sc);
  a.D_g = img(o.D_g, sc);
  a.D_b = img(o.D_b, sc);
  return a;
}

// Pass 2's backward over the forward's images fwd, from the scene's upstream gradients, into out.
BaseBwdArgs base_bwd_args(const Scene& sc, const BaseOut& fwd, std::vector<SplatGrad>& out) {
  BaseBwdArgs b{};
  b.view = sc.view;
  b.eps = 0.05f;
  b.splats = cspan(sc.splats);
  b.bins = {cspan(sc.values), cspan(sc.ranges)};
  b.D_t = cimg(sc.D_t, sc);
  b.W_g = cimg(fwd.W_g, sc);
  b.D_b = cimg(fwd.D_b, sc);
  b.C_b = cimg(fwd.C_b, sc);
  b.v_C_b = cimg(sc.v_C, sc);
  b.v_D_b = cimg(sc.v_D, sc);
  b.v_splats = {out.data(), int64_t(out.size())};
  return b;
}

// Pass 3 into C_r, W_r (plane 1 for PixelOnly).
ReflFwdArgs refl_fwd_args(const Scene& sc, PlaneMode mode, std::vector<Eigen::Vector3f>& C_r, std::vector<float>& W_r) {
  ReflFwdArgs a{};
  a.view = sc.view;
  a.splats = cspan(sc.splats);
  a.bins = {cspan(sc.values), cspan(sc.ranges)};
  a.plane_ids = cspan(sc.plane_ids);
  a.I = cimg(sc.I, sc);
  a.mode = mode;
  a.plane = 1;
  a.C_r = img(C_r, sc);
  a.W_r = img(W_r, sc);
  return a;
}

// Pass 3's backward over the forward's C_r, W_r, from the scene's upstream gradients, into out.
ReflBwdArgs refl_bwd_args(const Scene& sc, PlaneMode mode, const std::vector<Eigen::Vector3f>& C_r,
                          const std::vector<float>& W_r, std::vector<SplatGrad>& out) {
  ReflBwdArgs b{};
  b.view = sc.view;
  b.splats = cspan(sc.splats);
  b.bins = {cspan(sc.values), cspan(sc.ranges)};
  b.plane_ids = cspan(sc.plane_ids);
  b.I = cimg(sc.I, sc);
  b.mode = mode;
  b.plane = 1;
  b.C_r = cimg(C_r, sc);
  b.W_r = cimg(W_r, sc);
  b.v_C_r = cimg(sc.v_C, sc);
  b.v_splats = {out.data(), int64_t(out.size())};
  return b;
}

// Pass 3 composites front to back: every tile's list sorted by depth, as the binning does.
void sort_lists_by_depth(Scene& sc) {
  for (const TileRange& r : sc.ranges)
    std::stable_sort(sc.values.begin() + r.begin, sc.values.begin() + r.end,
                     [&](int32_t p, int32_t q) { return sc.splats[size_t(p)].depth < sc.splats[size_t(q)].depth; });
}

void expect_close(const SplatGrad& got, const SplatGrad& want, int g) {
  const float* a = &got.mean[0];
  const float* b = &want.mean[0];
  for (int k = 0; k < int(sizeof(SplatGrad) / sizeof(float)); ++k)
    EXPECT_NEAR(a[k], b[k], 1e-4f * (1.0f + std::abs(b[k]))) << "splat " << g << " field " << k;
}

TEST(RasterizeSchedule, NoPixelOutsideTheReachBoundHasAnAlpha) {
  std::mt19937 rng(7);
  int64_t inside_hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Splat s = random_splat(rng, 40, 40);
    int x0, y0, x1, y1;
    const bool any = splat_pixel_bounds(s, x0, y0, x1, y1);
    for (int y = -40; y < 90; ++y)
      for (int x = -40; x < 90; ++x) {
        const float alpha = splat_alpha(s, float(x), float(y), 1.0f);
        const bool in = any && x >= x0 && x <= x1 && y >= y0 && y <= y1;
        if (!in) ASSERT_EQ(alpha, 0.0f) << "splat " << i << " pixel " << x << "," << y;
        inside_hits += in && alpha > 0.0f ? 1 : 0;
      }
    if (s.opacity < kAlphaMin) EXPECT_FALSE(any);
  }
  EXPECT_GT(inside_hits, 100000);  // the bound is not empty where splats are visible
}

TEST(RasterizeSchedule, BoundIsTightToTheEllipse) {
  // An axis-aligned splat with sigma 2 px (x) and 1 px (y), opacity 1: alpha >= 1/255 out to
  // sqrt(2 ln 255) sigma = 3.33 sigma, so x in [-6, 6] and y in [-3, 3] around (20, 20).
  Splat s{};
  s.mean[0] = 20.0f;
  s.mean[1] = 20.0f;
  s.conic[0] = 1.0f / 4.0f;
  s.conic[1] = 0.0f;
  s.conic[2] = 1.0f;
  s.opacity = 1.0f;
  int x0, y0, x1, y1;
  ASSERT_TRUE(splat_pixel_bounds(s, x0, y0, x1, y1));
  EXPECT_EQ(x0, 14);
  EXPECT_EQ(x1, 26);
  EXPECT_EQ(y0, 17);
  EXPECT_EQ(y1, 23);
}

TEST(RasterizeSchedule, BasePassMatchesThePerPixelLoop) {
  Scene sc = make_scene(11, 300);
  const size_t n = sc.C_t.size();
  BaseOut tiled(n), pixel(n);
  CpuRasterScratch scratch = poisoned_scratch(sc);
  base_fwd_cpu(base_fwd_args(sc, tiled), scratch);
  base_fwd(CpuBackend{}, base_fwd_args(sc, pixel));
  int64_t covered = 0;
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(tiled.C_g[i][k], pixel.C_g[i][k], 1e-6f * (1.0f + std::abs(pixel.C_g[i][k]))) << i;
      EXPECT_NEAR(tiled.C_b[i][k], pixel.C_b[i][k], 1e-6f) << i;
    }
    EXPECT_NEAR(tiled.W_g[i], pixel.W_g[i], 1e-6f * (1.0f + pixel.W_g[i])) << i;
    EXPECT_NEAR(tiled.D_g[i], pixel.D_g[i], 1e-6f * (1.0f + pixel.D_g[i])) << i;
    EXPECT_NEAR(tiled.D_b[i], pixel.D_b[i], 1e-6f * (1.0f + pixel.D_b[i])) << i;
    covered += pixel.W_g[i] > 0.0f ? 1 : 0;
  }
  EXPECT_GT(covered, int64_t(n) * 9 / 10);
  // The CPU forward evaluates a splat on eight pixels of a row at once (rasterize_cpu.cpp); with
  // the same splats in the same order per pixel and no fused multiply-adds, its images are the
  // per-pixel loop's bit for bit.
  EXPECT_EQ(std::memcmp(tiled.C_g.data(), pixel.C_g.data(), n * sizeof(Eigen::Vector3f)), 0);
  EXPECT_EQ(std::memcmp(tiled.W_g.data(), pixel.W_g.data(), n * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(tiled.D_g.data(), pixel.D_g.data(), n * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(tiled.C_b.data(), pixel.C_b.data(), n * sizeof(Eigen::Vector3f)), 0);
  EXPECT_EQ(std::memcmp(tiled.D_b.data(), pixel.D_b.data(), n * sizeof(float)), 0);

  // Backward from random upstream gradients (zero at some pixels).
  std::vector<SplatGrad> g_tiled(sc.splats.size(), SplatGrad{}), g_pixel(sc.splats.size(), SplatGrad{});
  BaseBwdArgs b = base_bwd_args(sc, pixel, g_tiled);
  {
    CpuRasterScratch fresh;  // no forward pass in it
    EXPECT_THROW(base_bwd_cpu(b, fresh), std::logic_error);
  }
  base_bwd_cpu(b, scratch);  // the falloffs of the tiled forward above
  b.v_splats = {g_pixel.data(), int64_t(g_pixel.size())};
  base_bwd(CpuBackend{}, b);
  int nonzero = 0;
  for (size_t g = 0; g < g_pixel.size(); ++g) {
    expect_close(g_tiled[g], g_pixel[g], int(g));
    nonzero += is_zero(g_pixel[g]) ? 0 : 1;
  }
  EXPECT_GT(nonzero, 200);
}

class ReflSchedule : public ::testing::TestWithParam<PlaneMode> {};

TEST_P(ReflSchedule, ReflectionPassMatchesThePerPixelLoop) {
  Scene sc = make_scene(23, 300);
  sort_lists_by_depth(sc);
  const size_t n = sc.C_t.size();
  std::vector<Eigen::Vector3f> C_tiled(n), C_pixel(n);
  std::vector<float> W_tiled(n), W_pixel(n);
  ReflFwdArgs a = refl_fwd_args(sc, GetParam(), C_tiled, W_tiled);
  CpuRasterScratch scratch = poisoned_scratch(sc);
  refl_fwd_cpu(a, scratch);
  a.C_r = img(C_pixel, sc);
  a.W_r = img(W_pixel, sc);
  refl_fwd(CpuBackend{}, a);
  int64_t saturated = 0;
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(C_tiled[i][k], C_pixel[i][k], 1e-6f) << i;
    EXPECT_NEAR(W_tiled[i], W_pixel[i], 1e-6f) << i;
    saturated += W_pixel[i] > 0.99f ? 1 : 0;
  }
  EXPECT_GT(saturated, 0);  // early termination is exercised

  std::vector<SplatGrad> g_tiled(sc.splats.size()), g_pixel(sc.splats.size());
  ReflBwdArgs b = refl_bwd_args(sc, GetParam(), C_pixel, W_pixel, g_tiled);
  {
    CpuRasterScratch fresh;  // no forward pass in it
    EXPECT_THROW(refl_bwd_cpu(b, fresh), std::logic_error);
  }
  refl_bwd_cpu(b, scratch);  // the reach of the tiled forward above
  b.v_splats = {g_pixel.data(), int64_t(g_pixel.size())};
  refl_bwd(CpuBackend{}, b);
  int nonzero = 0;
  for (size_t g = 0; g < g_pixel.size(); ++g) {
    expect_close(g_tiled[g], g_pixel[g], int(g));
    nonzero += is_zero(g_pixel[g]) ? 0 : 1;
  }
  EXPECT_GT(nonzero, 100);
}

INSTANTIATE_TEST_SUITE_P(Modes, ReflSchedule,
                         ::testing::Values(PlaneMode::Match, PlaneMode::All, PlaneMode::PixelOnly));

// Sets the OpenMP thread count while in scope.
struct Threads {
  int saved = omp_get_max_threads();
  explicit Threads(int n) { omp_set_num_threads(n); }
  ~Threads() { omp_set_num_threads(saved); }
};

bool bitwise_equal(const std::vector<SplatGrad>& a, const std::vector<SplatGrad>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(SplatGrad)) == 0;
}

// Both backward passes, on one thread and repeatedly on several: the same gradients bit for bit.
// (With atomic adds per (tile, splat), as before, the sums' order followed the threads' progress
// and the last bits differed between runs.) Many splats reach many tiles here, so each splat's
// gradient is a sum over several tiles' entries.
TEST(RasterizeSchedule, BackwardGradientsDoNotDependOnTheThreadCount) {
  Scene sc = make_scene(5, 300);
  sort_lists_by_depth(sc);
  const size_t n = sc.C_t.size();
  BaseOut fwd(n);
  {
    CpuRasterScratch unused;
    base_fwd_cpu(base_fwd_args(sc, fwd), unused);
  }
  std::vector<Eigen::Vector3f> C_r(n);
  std::vector<float> W_r(n);
  {
    CpuRasterScratch unused;
    refl_fwd_cpu(refl_fwd_args(sc, PlaneMode::Match, C_r, W_r), unused);
  }

  const auto backward = [&](int64_t max_kept_pairs = kMaxKeptPairs) {
    std::vector<SplatGrad> base(sc.splats.size(), SplatGrad{}), refl(sc.splats.size(), SplatGrad{});
    CpuRasterScratch scratch = poisoned_scratch(sc);
    scratch.max_kept_pairs = max_kept_pairs;
    BaseOut again(n);
    base_fwd_cpu(base_fwd_args(sc, again), scratch);  // on this thread count too
    EXPECT_EQ(std::memcmp(again.C_b.data(), fwd.C_b.data(), n * sizeof(Eigen::Vector3f)), 0);
    base_bwd_cpu(base_bwd_args(sc, fwd, base), scratch);
    // pass 3 in the same scratch: its backward must not carry pass 2's entries
    std::vector<Eigen::Vector3f> C_again(n);
    std::vector<float> W_again(n);
    refl_fwd_cpu(refl_fwd_args(sc, PlaneMode::Match, C_again, W_again), scratch);
    EXPECT_EQ(std::memcmp(C_again.data(), C_r.data(), n * sizeof(Eigen::Vector3f)), 0);
    refl_bwd_cpu(refl_bwd_args(sc, PlaneMode::Match, C_r, W_r, refl), scratch);
    return std::pair{base, refl};
  };
  std::pair<std::vector<SplatGrad>, std::vector<SplatGrad>> one;
  {
    const Threads t(1);
    one = backward();
  }
  int nonzero = 0;
  for (const SplatGrad& g : one.first) nonzero += is_zero(g) ? 0 : 1;
  EXPECT_GT(nonzero, 200);
  {  // the falloffs not kept (a render with more pairs than the cap): evaluated again, the same
    const Threads t(1);
    const auto again = backward(0);
    EXPECT_TRUE(bitwise_equal(again.first, one.first)) << "falloffs evaluated again in the backward";
  }
  for (const int threads : {2, 3, 4})
    for (int rep = 0; rep < 4; ++rep) {
      const Threads t(threads);
      const auto many = backward();
      EXPECT_TRUE(bitwise_equal(many.first, one.first)) << threads << " threads, run " << rep << " (pass 2)";
      EXPECT_TRUE(bitwise_equal(many.second, one.second)) << threads << " threads, run " << rep << " (pass 3)";
    }
}

}  // namespace
}  // namespace rrg::kernel
