// The mapping loss per iteration (paper §4.2: L1 + λ(1 − SSIM) on C, L1 on D_b, the Sobel term on
// C_r; ours: λ_rb on R·C_b) with its image gradients, and SSIM alone, on random images at the mapping resolutions, on
// every available device. Names: losses_<what>_<w>x<h>/<device>.
#include "core/gaussians/losses.h"

#include <benchmark/benchmark.h>

#include <random>

namespace {

struct Images {
  rrg::DeviceImage<rrg::Color> C, C_gt, C_r, v_C, v_C_r;
  rrg::DeviceImage<float> D, D_gt, v_D, R;
};

Images images(int w, int h, const rrg::Device& device) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), z(0.5f, 4.0f);
  rrg::ColorImage c(w, h), c_gt(w, h), c_r(w, h);
  rrg::Image<float> d(w, h), d_gt(w, h), r(w, h);
  for (size_t i = 0; i < c.size(); ++i) {
    c[i] = rrg::Color(u(rng), u(rng), u(rng));
    c_gt[i] = rrg::Color(u(rng), u(rng), u(rng));
    c_r[i] = rrg::Color(u(rng), u(rng), u(rng)) * 0.2f;
    d[i] = z(rng);
    d_gt[i] = u(rng) < 0.1f ? 0.0f : z(rng);  // a tenth without depth
    r[i] = i % size_t(w) < size_t(w) / 3 ? 1.0f : 0.0f;  // a third of the image reflective
  }
  Images im;
  im.C = rrg::DeviceImage<rrg::Color>::from_host(c, device);
  im.C_gt = rrg::DeviceImage<rrg::Color>::from_host(c_gt, device);
  im.C_r = rrg::DeviceImage<rrg::Color>::from_host(c_r, device);
  im.D = rrg::DeviceImage<float>::from_host(d, device);
  im.D_gt = rrg::DeviceImage<float>::from_host(d_gt, device);
  im.R = rrg::DeviceImage<float>::from_host(r, device);
  return im;
}

void BM_MappingLoss(benchmark::State& state, rrg::Device device, int w, int h) {
  Images im = images(w, h, device);
  rrg::LossScratch scratch;
  const rrg::LossWeights weights;
  const rrg::ReflectionImages refl{im.C_r, im.C, im.R};  // C stands in for C_b
  for (auto _ : state) {
    const rrg::LossValues L =
        rrg::mapping_loss(im.C, im.C_gt, im.D, im.D_gt, &refl, weights, im.v_C, im.v_D, im.v_C_r, scratch);
    benchmark::DoNotOptimize(L.total);
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_Ssim(benchmark::State& state, rrg::Device device, int w, int h, bool gradient) {
  Images im = images(w, h, device);
  im.v_C = rrg::DeviceImage<rrg::Color>(w, h, device);
  rrg::Buffer<float> scratch;
  for (auto _ : state) {
    const float s = rrg::ssim(im.C, im.C_gt, gradient ? &im.v_C : nullptr, -0.2f, scratch);
    benchmark::DoNotOptimize(s);
  }
}

const bool registered = [] {
  for (const rrg::Device& device : rrg::available_devices())
    for (auto [w, h] : {std::pair{320, 240}, std::pair{640, 480}, std::pair{1280, 720}}) {
      const std::string tag = std::to_string(w) + "x" + std::to_string(h) + "/" + device.to_string();
      benchmark::RegisterBenchmark(("losses_mapping_" + tag).c_str(), BM_MappingLoss, device, w, h)
          ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
      benchmark::RegisterBenchmark(("losses_ssim_" + tag).c_str(), BM_Ssim, device, w, h, false)
          ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
      benchmark::RegisterBenchmark(("losses_ssim_grad_" + tag).c_str(), BM_Ssim, device, w, h, true)
          ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(0.5);
    }
  return true;
}();

}  // namespace
