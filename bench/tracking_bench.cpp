// Tracking stage 1 at 640x480 on every available device (paper §4.1.2; the paper reports
// 0.85 ms for tracking on its GPU): preprocessing (bilateral filter, 3-level pyramid, vertex and
// normal maps), one ICP reduction at level 0, and a whole ICP (10/5/4 Gauss-Newton steps, coarse to
// fine) against a model raycast. Scene: the inside of a 4 m box seen towards a corner, the frame
// 3 cm / 2° away from the model's camera. Host<->device copies excluded.
#include "core/tracking/icp.h"
#include "core/tracking/preprocess.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <limits>

namespace {

using rrg::Intrinsics;
const Intrinsics kK{525.0f, 525.0f, 319.5f, 239.5f, 640, 480};

struct Render {
  rrg::DepthImage depth{640, 480, 0.0f};
  rrg::Image<Eigen::Vector3f> vertices{640, 480, Eigen::Vector3f::Zero()}, normals{640, 480, Eigen::Vector3f::Zero()};
};

// Ray casting of the box [-2, 2]³ from inside.
Render render(const Eigen::Isometry3f& T_wc) {
  Render r;
  const Eigen::Vector3f o = T_wc.translation();
  for (int y = 0; y < kK.height; ++y)
    for (int x = 0; x < kK.width; ++x) {
      const Eigen::Vector3f d = T_wc.linear() * Eigen::Vector3f((x - kK.cx) / kK.fx, (y - kK.cy) / kK.fy, 1.0f);
      float best = std::numeric_limits<float>::infinity();
      Eigen::Vector3f n = Eigen::Vector3f::Zero();
      for (int a = 0; a < 3; ++a)
        for (float s : {-1.0f, 1.0f}) {
          if (d[a] * s <= 1e-6f) continue;  // wall at coordinate a = 2s, hit when moving towards it
          const float t = (2.0f * s - o[a]) / d[a];
          if (t > 0 && t < best) best = t, n = -s * Eigen::Vector3f::Unit(a);
        }
      r.depth(x, y) = best;
      r.vertices(x, y) = o + best * d;
      r.normals(x, y) = n;
    }
  return r;
}

Eigen::Isometry3f camera() {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), Eigen::Vector3f(1, 0.8f, 0.6f)).toRotationMatrix();
  T.translation() = Eigen::Vector3f(-0.5f, -0.4f, -0.3f);
  return T;
}

struct Fixture {
  Eigen::Isometry3f T_ref = camera(), T_cur;
  rrg::DeviceImage<float> depth;
  rrg::DeviceImage<Eigen::Vector3f> model_v, model_n;
  explicit Fixture(const rrg::Device& device) {
    Eigen::Isometry3f delta = Eigen::Isometry3f::Identity();
    delta.rotate(Eigen::AngleAxisf(0.035f, Eigen::Vector3f(0.3f, 1.0f, -0.2f).normalized()));
    delta.translation() = Eigen::Vector3f(0.02f, -0.015f, 0.015f);
    T_cur = T_ref * delta;
    const Render model = render(T_ref), frame = render(T_cur);
    depth = rrg::DeviceImage<float>::from_host(frame.depth, device);
    model_v = rrg::DeviceImage<Eigen::Vector3f>::from_host(model.vertices, device);
    model_n = rrg::DeviceImage<Eigen::Vector3f>::from_host(model.normals, device);
  }
  rrg::IcpModel model() const { return {&model_v, &model_n, kK, T_ref}; }
};

void BM_Preprocess(benchmark::State& state, rrg::Device device) {
  const Fixture f(device);
  for (auto _ : state) {
    auto pyr = rrg::build_pyramid(f.depth, kK, rrg::PreprocessParams{});
    benchmark::DoNotOptimize(pyr.levels.back().maps.normals.buffer().data());
  }
}

void BM_IcpReduceLevel0(benchmark::State& state, rrg::Device device) {
  const Fixture f(device);
  const auto pyr = rrg::build_pyramid(f.depth, kK, rrg::PreprocessParams{});
  for (auto _ : state) benchmark::DoNotOptimize(rrg::reduce_icp_system(pyr.levels[0].maps, f.model(), f.T_ref, {}));
}

void BM_IcpAlign(benchmark::State& state, rrg::Device device) {
  const Fixture f(device);
  const auto pyr = rrg::build_pyramid(f.depth, kK, rrg::PreprocessParams{});
  int iterations = 0;
  for (auto _ : state) {
    const rrg::IcpResult r = rrg::icp_align(pyr, f.model(), f.T_ref, {});
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.T_wc);
  }
  state.counters["gn_steps"] = iterations;
}

const bool registered = [] {
  for (const rrg::Device& device : rrg::available_devices()) {
    const std::string d = device.to_string();
    benchmark::RegisterBenchmark(("tracking_preprocess_640x480/" + d).c_str(), BM_Preprocess, device)
        ->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark(("tracking_icp_reduce_640x480/" + d).c_str(), BM_IcpReduceLevel0, device)
        ->Unit(benchmark::kMillisecond)->UseRealTime();
    benchmark::RegisterBenchmark(("tracking_icp_align_640x480/" + d).c_str(), BM_IcpAlign, device)
        ->Unit(benchmark::kMillisecond)->UseRealTime();
  }
  return true;
}();

}  // namespace
