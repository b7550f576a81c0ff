// Densification of one frame on the host (core/gaussians/densify.h), the part of a mapping step
// that stays on the CPU with either back end: a 1280x720 view in which a mirror (a reflective plane
// 1.5 m ahead) covers the middle third of the image and nothing is fitted yet, so every sampled
// mirror pixel becomes ten reflection Gaussians along its ray, and every other pixel with depth a
// base Gaussian candidate. Reports ms per call and the Gaussians made, for batches of SH degree 0
// (what the mapper makes since the sixteenth session) and 3 (before).
#include "core/gaussians/densify.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

struct View {
  rrg::Intrinsics K{1024.0f, 1024.0f, 639.5f, 359.5f, 1280, 720};
  rrg::ColorImage C_gt, C, C_b;
  rrg::DepthImage D_gt;
  rrg::Image<float> W_b, W_r, C_var;
  rrg::MaskImage R;
  rrg::Image<int32_t> I;
  std::vector<rrg::ReflectivePlane> planes;
  rrg::DensifyView view() const {
    rrg::DensifyView v;
    v.K = K;
    v.C_gt = &C_gt, v.C = &C, v.C_b = &C_b, v.D_gt = &D_gt;
    v.W_b = &W_b, v.W_r = &W_r, v.C_var = &C_var, v.R = &R, v.I = &I;
    return v;
  }
};

View make_view() {
  View s;
  const int w = s.K.width, h = s.K.height;
  s.C_gt = rrg::ColorImage(w, h, rrg::Color(0.8f, 0.6f, 0.4f));
  s.C = rrg::ColorImage(w, h, rrg::Color(0.1f, 0.1f, 0.1f));  // nothing fitted: every pixel is wrong
  s.C_b = s.C;
  s.D_gt = rrg::DepthImage(w, h, 0.0f);
  s.W_b = rrg::Image<float>(w, h, 0.0f);
  s.W_r = rrg::Image<float>(w, h, 0.0f);
  s.C_var = rrg::Image<float>(w, h, 0.1f);
  s.R = rrg::MaskImage(w, h, 0);
  s.I = rrg::Image<int32_t>(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // A wall 3 m ahead, tilted so depth varies; the mirror in the middle third at 1.5 m.
      const bool mirror = x >= w / 3 && x < 2 * w / 3;
      s.D_gt(x, y) = mirror ? 1.5f : 3.0f + 0.001f * float(x);
      s.R(x, y) = mirror ? 1 : 0;
      s.I(x, y) = mirror ? 7 : 0;
      s.C_gt(x, y) = rrg::Color(0.3f + 0.5f * float(x % 17) / 17.0f, 0.6f, 0.2f + 0.6f * float(y % 13) / 13.0f);
    }
  s.planes.push_back({7, Eigen::Vector4f(0.0f, 0.0f, -1.0f, 1.5f)});  // z = 1.5 in the camera (= world) frame
  return s;
}

// degree: SH degree of the batch made (the mapper asks for 0, DC only; 3 is the set's degree).
void BM_densify_reflection(benchmark::State& state, int degree) {
  const View s = make_view();
  const rrg::DensifyParams p;
  size_t made = 0;
  for (auto _ : state) {
    const rrg::GaussianHost g = rrg::densify_reflection(s.view(), s.planes, p, degree, 42);
    made = g.size();
    benchmark::DoNotOptimize(g.means.data());
  }
  state.counters["gaussians"] = double(made);
}
BENCHMARK_CAPTURE(BM_densify_reflection, sh0, 0)->Name("densify_reflection_1280x720/sh0/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_densify_reflection, sh3, 3)->Name("densify_reflection_1280x720/sh3/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_densify_base(benchmark::State& state, int degree) {
  const View s = make_view();
  const rrg::DensifyParams p;
  size_t made = 0;
  for (auto _ : state) {
    const rrg::GaussianHost g = rrg::densify_base(s.view(), p, degree, 42);
    made = g.size();
    benchmark::DoNotOptimize(g.means.data());
  }
  state.counters["gaussians"] = double(made);
}
BENCHMARK_CAPTURE(BM_densify_base, sh0, 0)->Name("densify_base_1280x720/sh0/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_densify_base, sh3, 3)->Name("densify_base_1280x720/sh3/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
