// ORB extraction of one frame (core/tracking/orb_features.h: OpenCV ORB, 1000 features, 8 levels,
// with and without a tracking mask excluding the middle third), at 320x240 and 1280x720 on the
// host: the part of tracking stage 2 that runs on the CPU with either back end. The image is a
// deterministic texture of blobs and edges at several scales, so FAST finds corners on every
// pyramid level; depth 2 m everywhere. Reports ms per frame and the keypoints found.
#include "core/tracking/orb_features.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

struct Frame {
  rrg::Intrinsics K;
  rrg::ColorImage color;
  rrg::DepthImage depth;
  rrg::MaskImage mask;
};

Frame make_frame(int w, int h) {
  Frame f;
  const float fx = 0.8f * float(w);
  f.K = rrg::Intrinsics{fx, fx, 0.5f * float(w - 1), 0.5f * float(h - 1), w, h};
  f.color = rrg::ColorImage(w, h, rrg::Color::Zero());
  f.depth = rrg::DepthImage(w, h, 2.0f);
  f.mask = rrg::MaskImage(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = float(x) / float(w), v = float(y) / float(h);
      float g = 0.5f;
      for (int octave = 0; octave < 4; ++octave) {  // blocky texture: corners at 4 scales
        const float s = float(8 << octave);
        const int cx = int(u * s), cy = int(v * s);
        g += (((cx * 73856093) ^ (cy * 19349663) ^ (octave * 83492791)) & 1 ? 0.12f : -0.12f);
      }
      f.color(x, y) = rrg::Color(g, 0.8f * g, 0.6f * g).cwiseMax(0.0f).cwiseMin(1.0f);
      f.mask(x, y) = x >= w / 3 && x < 2 * w / 3;
    }
  return f;
}

void BM_orb(benchmark::State& state, int w, int h, bool masked) {
  const Frame f = make_frame(w, h);
  const rrg::OrbParams p;
  size_t keypoints = 0;
  for (auto _ : state) {
    const rrg::OrbFrame o = rrg::extract_orb(f.color, f.depth, f.K, masked ? &f.mask : nullptr, p);
    keypoints = o.keypoints.size();
    benchmark::DoNotOptimize(o.descriptors.data);
  }
  state.counters["keypoints"] = double(keypoints);
}
BENCHMARK_CAPTURE(BM_orb, 320x240, 320, 240, false)->Name("orb_extract_320x240/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_orb, 320x240_masked, 320, 240, true)->Name("orb_extract_320x240_masked/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_orb, 1280x720, 1280, 720, false)->Name("orb_extract_1280x720/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_orb, 1280x720_masked, 1280, 720, true)->Name("orb_extract_1280x720_masked/cpu")->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
