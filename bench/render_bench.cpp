// Three-pass renderer (paper §3.2): ms per stage (projection + binning, pass 2 base, pass 3
// reflection incl. its depth sort, composite, backward) at 640x480 and 1280x720 with 100k and 300k
// Gaussians per set, for the three reflection variants side by side, on every available device.
// Host<->device copies excluded. The scene: Gaussians spread over the frustum at 1-6 m with screen
// std of ~1-4 px (at 640x480), a TSDF surface at 2-4 m, four planes (floor, wall, table, screen)
// covering ~80% of the image, R = 1 on them. Filter with --benchmark_filter=render/cpu etc.
#include "core/render/renderer.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

namespace {

using namespace rrg;

// n Gaussians in the frustum at depths z0..z1, then `away` more that no pixel can see: half behind
// the camera, half in front of it but outside the field of view (the rest of a map larger than the
// view, as in a room scanned from its middle).
GaussianHost bench_gaussians(int n, float z0, float z1, bool planes, uint32_t seed, int away = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f);
  GaussianHost g(3);
  g.resize(size_t(n + away));
  const float f640 = 525.0f;
  for (int i = 0; i < n + away; ++i) {
    const float z = z0 + (z1 - z0) * u01(rng);
    g.means[i] = {0.62f * z * u(rng), 0.47f * z * u(rng), z};
    if (i >= n && i % 2 == 0) g.means[i].z() = -z;  // behind the camera
    if (i >= n && i % 2 == 1) g.means[i].x() = (u(rng) < 0 ? -1.0f : 1.0f) * z * (1.5f + u01(rng));  // beside the view
    for (int a = 0; a < 3; ++a) g.log_scales[i][a] = std::log(z / f640 * (1.0f + 3.0f * u01(rng)));
    g.quats[i] = Eigen::Vector4f(u(rng), u(rng), u(rng), u(rng)) + Eigen::Vector4f(0.5f, 0, 0, 0);
    g.logit_opacities[i] = 2.0f * u(rng);
    for (int k = 0; k < 16; ++k) g.sh[size_t(i) * 16 + k] = Eigen::Vector3f(u(rng), u(rng), u(rng)) * (k ? 0.1f : 0.8f);
    g.plane_ids[i] = planes ? 1 + int32_t(i % 4) : 0;
  }
  return g;
}

struct Scene {
  RenderCamera camera;
  std::unique_ptr<GaussianSet> base, refl;
  RaycastInputs raycast;
  RenderUpstream upstream;
};

Scene make_scene(int w, int h, int n, int away, const Device& device) {
  Scene s;
  const float f = 525.0f * float(w) / 640.0f;
  s.camera.K = {f, f, 0.5f * float(w - 1), 0.5f * float(h - 1), w, h};
  s.base = std::make_unique<GaussianSet>(GaussianSet::from_host(bench_gaussians(n, 1.0f, 4.5f, false, 1, away), device));
  s.refl = std::make_unique<GaussianSet>(GaussianSet::from_host(bench_gaussians(n, 2.5f, 6.0f, true, 2, away), device));
  ColorImage C_t(w, h), v_C(w, h);
  DepthImage D_t(w, h), v_D(w, h);
  Image<int32_t> I(w, h);
  Image<float> R(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float fx = float(x) / float(w), fy = float(y) / float(h);
      C_t(x, y) = {fx, fy, 0.5f};
      D_t(x, y) = 2.0f + 2.0f * fy;
      I(x, y) = fy > 0.7f ? 1 : (fx < 0.3f ? 2 : (fx < 0.6f ? 3 : (fy < 0.1f ? 0 : 4)));
      R(x, y) = I(x, y) ? 1.0f : 0.0f;
      v_C(x, y) = {0.1f * (fx - 0.5f), 0.1f * (fy - 0.5f), 0.05f};
      v_D(x, y) = 0.02f * (fx - fy);
    }
  s.raycast = {DeviceImage<Color>::from_host(C_t, device), DeviceImage<float>::from_host(D_t, device),
               DeviceImage<int32_t>::from_host(I, device), DeviceImage<float>::from_host(R, device)};
  s.upstream = {DeviceImage<Color>::from_host(v_C, device), DeviceImage<float>::from_host(v_D, device), {}};
  return s;
}

void BM_Render(benchmark::State& state, Device device, int w, int h, int n, int away, ReflectionVariant variant) {
  Scene s = make_scene(w, h, n, away, device);
  RenderParams p;
  p.variant = variant;
  p.time_stages = true;
  Renderer renderer(device, p);
  RenderOutputs out;
  GaussianGrads gb, gr;
  RenderTimings sum;
  for (auto _ : state) {
    renderer.render(s.camera, *s.base, *s.refl, s.raycast, out);
    renderer.backward(s.upstream, gb, gr);
    const RenderTimings& t = renderer.timings();
    sum.project_ms += t.project_ms;
    sum.base_ms += t.base_ms;
    sum.reflection_ms += t.reflection_ms;
    sum.composite_ms += t.composite_ms;
    sum.backward_ms += t.backward_ms;
  }
  const double k = 1.0 / double(state.iterations());
  state.counters["proj_bin_ms"] = sum.project_ms * k;
  state.counters["base_ms"] = sum.base_ms * k;
  state.counters["refl_ms"] = sum.reflection_ms * k;
  state.counters["comp_ms"] = sum.composite_ms * k;
  state.counters["fwd_ms"] = (sum.project_ms + sum.base_ms + sum.reflection_ms + sum.composite_ms) * k;
  state.counters["bwd_ms"] = sum.backward_ms * k;
  state.counters["base_entries"] = double(renderer.base_entries());
  state.counters["refl_entries"] = double(renderer.reflection_entries());
}

const bool registered = [] {
  for (const Device& device : available_devices())
    for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}})
      for (int n : {100000, 300000})
        for (auto v : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping, ReflectionVariant::MultiPass}) {
          const std::string name = "render/" + device.to_string() + "/" + std::to_string(w) + "x" + std::to_string(h) +
                                   "/" + std::to_string(n / 1000) + "k/" + to_string(v);
          benchmark::RegisterBenchmark(name.c_str(), BM_Render, device, w, h, n, 0, v)
              ->Unit(benchmark::kMillisecond)
              ->UseRealTime()
              ->Iterations(device.is_cpu() ? 2 : 20);
        }
  // A map five times the view: 100k Gaussians per set in view and 400k per set out of it. Against
  // render/<device>/640x480/100k/grouped, what the out-of-view part of a map costs per iteration.
  for (const Device& device : available_devices())
    benchmark::RegisterBenchmark(("render/" + device.to_string() + "/640x480/100k+400k-away/grouped").c_str(), BM_Render,
                                 device, 640, 480, 100000, 400000, ReflectionVariant::Grouped)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->Iterations(device.is_cpu() ? 4 : 20);
  return true;
}();

}  // namespace
