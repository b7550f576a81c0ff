// Vertex + normal maps (paper §4.1.1) at 640x480 on every available device, host<->device copies
// excluded (the pipeline keeps frames on the device). Reports ms per frame and frames/s.
#include "core/common/depth_maps.h"

#include <benchmark/benchmark.h>

namespace {

const rrg::Intrinsics kK{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};

// A slanted plane, plus a small per-pixel pattern when jitter > 0 (a noisy sensor's depth).
rrg::DepthImage plane_depth(float jitter) {
  rrg::DepthImage depth(kK.width, kK.height);
  for (int y = 0; y < kK.height; ++y)
    for (int x = 0; x < kK.width; ++x)
      depth(x, y) = 1.0f + 0.002f * x + 0.001f * y + jitter * float((x * 7 + y * 13) % 5 - 2);
  return depth;
}

void BM_VertexNormalMaps(benchmark::State& state, rrg::Device device) {
  const auto d = rrg::DeviceImage<float>::from_host(plane_depth(0.0f), device);
  for (auto _ : state) {
    auto maps = rrg::compute_vertex_normal_maps(d, kK);
    benchmark::DoNotOptimize(maps.normals.buffer().data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// As preprocessing runs it: V from the sensor's depth, N from another (the bilateral-filtered) one,
// into maps kept from frame to frame.
void BM_VertexNormalMapsTwoDepths(benchmark::State& state, rrg::Device device) {
  const auto d = rrg::DeviceImage<float>::from_host(plane_depth(0.001f), device);
  const auto s = rrg::DeviceImage<float>::from_host(plane_depth(0.0f), device);
  rrg::VertexNormalMaps maps;
  for (auto _ : state) {
    rrg::compute_vertex_normal_maps_into(maps, d, s, kK);
    benchmark::DoNotOptimize(maps.normals.buffer().data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

const bool registered = [] {
  for (const rrg::Device& device : rrg::available_devices())
    benchmark::RegisterBenchmark(("vertex_normal_maps_640x480/" + device.to_string()).c_str(),
                                 BM_VertexNormalMaps, device)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  for (const rrg::Device& device : rrg::available_devices())
    benchmark::RegisterBenchmark(("vertex_normal_maps_two_depths_640x480/" + device.to_string()).c_str(),
                                 BM_VertexNormalMapsTwoDepths, device)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  return true;
}();

}  // namespace

BENCHMARK_MAIN();
