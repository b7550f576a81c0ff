// Vertex + normal maps (paper §4.1.1) at 640x480 on every available device, host<->device copies
// excluded (the pipeline keeps frames on the device). Reports ms per frame and frames/s.
#include "core/common/depth_maps.h"

#include <benchmark/benchmark.h>

namespace {

void BM_VertexNormalMaps(benchmark::State& state, rrg::Device device) {
  const rrg::Intrinsics K{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};
  rrg::DepthImage depth(640, 480);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) depth(x, y) = 1.0f + 0.002f * x + 0.001f * y;
  const auto d = rrg::DeviceImage<float>::from_host(depth, device);
  for (auto _ : state) {
    auto maps = rrg::compute_vertex_normal_maps(d, K);
    benchmark::DoNotOptimize(maps.normals.buffer().data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

// As preprocessing runs it: V from the sensor's depth, N from another (the bilateral-filtered) one.
void BM_VertexNormalMapsTwoDepths(benchmark::State& state, rrg::Device device) {
  const rrg::Intrinsics K{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};
  rrg::DepthImage depth(640, 480), smooth(640, 480);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      smooth(x, y) = 1.0f + 0.002f * x + 0.001f * y;
      depth(x, y) = smooth(x, y) + 0.001f * float((x * 7 + y * 13) % 5 - 2);
    }
  const auto d = rrg::DeviceImage<float>::from_host(depth, device);
  const auto s = rrg::DeviceImage<float>::from_host(smooth, device);
  rrg::VertexNormalMaps maps;
  for (auto _ : state) {
    rrg::compute_vertex_normal_maps_into(maps, d, s, K);
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
