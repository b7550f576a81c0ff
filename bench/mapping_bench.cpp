// Gaussian mapping step (paper §4.2): ms per step of 30 iterations over N_local = 2 + N_global = 7
// frames (densify → optimise → prune), at 320x240 and 640x480, on every available device. Scene:
// the living_room preset with ground-truth poses, 30 frames (every 3rd of the loop), TSDF (1 cm
// voxels) fused from them; a keyframe every 5th frame. Two warm-up steps build the map, then each
// timed step gets 10 new frames (cycled). Counters: per-stage ms and the map size after the step.
#include "core/slam/mapper.h"
#include "core/synth/renderer.h"
#include "core/synth/sequence.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_raycast.h"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

namespace {

using namespace rrg;

struct MappingScene {
  Intrinsics K;
  std::vector<MappingFrame> frames;
  std::unique_ptr<TsdfVolume> volume;
};

MappingScene make_scene(int width, int height, const Device& device) {
  const synth::SceneSpec spec = synth::make_preset("living_room", 0);
  synth::SynthParams sp;
  sp.width = width;
  sp.height = height;
  sp.frames = 90;
  const synth::SequencePlan plan = synth::plan_sequence(spec, synth::make_camera_path(spec), sp);
  MappingScene s;
  s.K = plan.K;
  TsdfParams tp;
  tp.voxel_size = 0.01f;
  s.volume = std::make_unique<TsdfVolume>(tp, device);
  for (int i = 0; i < 30; ++i) {
    const Eigen::Isometry3f T = plan.frames[size_t(3 * i)].T_wc.cast<float>();
    const synth::RenderOutput r = synth::render_view(spec.scene, s.K, T);
    integrate(*s.volume, DeviceImage<float>::from_host(r.depth, device), DeviceImage<Color>::from_host(r.color, device),
              s.K, T);
    s.frames.push_back(MappingFrame{i, T, r.color, r.depth});
  }
  return s;
}

void BM_MappingStep(benchmark::State& state, int width, int height, Device device) {
  const MappingScene s = make_scene(width, height, device);
  MappingContext ctx;
  // What the session's mapping context asks for: no V*, N* (core/slam/session.cpp).
  ctx.raycast = [&s](const Intrinsics& K, const Eigen::Isometry3f& T) {
    return raycast(*s.volume, K, T, {}, RaycastOutputs{.color = true, .reflection = true, .normals = false});
  };
  GaussianMapper mapper(MapperParams{}, s.K, device);
  int64_t next = 0;
  auto feed = [&] {
    for (int k = 0; k < 10; ++k, ++next) {
      MappingFrame f = s.frames[size_t(next % int64_t(s.frames.size()))];
      f.index = next;
      mapper.add_frame(std::move(f), next % 5 == 0);
    }
  };
  for (int warm = 0; warm < 2; ++warm) {
    feed();
    mapper.step(ctx);
  }
  MappingStats sum;
  int steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    feed();
    state.ResumeTiming();
    const MappingStats st = mapper.step(ctx);
    sum.ms_raycast += st.ms_raycast;
    sum.ms_densify += st.ms_densify;
    sum.ms_optimise += st.ms_optimise;
    sum.ms_prune += st.ms_prune;
    sum.base_size = st.base_size;
    sum.reflection_size = st.reflection_size;
    ++steps;
  }
  state.counters["raycast_ms"] = sum.ms_raycast / steps;
  state.counters["densify_ms"] = sum.ms_densify / steps;
  state.counters["optimise_ms"] = sum.ms_optimise / steps;
  state.counters["prune_ms"] = sum.ms_prune / steps;
  state.counters["base_gaussians"] = double(sum.base_size);
}

const bool registered = [] {
  for (const Device& d : available_devices())
    for (auto [w, h] : {std::pair{320, 240}, std::pair{640, 480}})
      benchmark::RegisterBenchmark(("mapping_step/" + d.to_string() + "/" + std::to_string(w) + "x" + std::to_string(h)).c_str(),
                                   BM_MappingStep, w, h, d)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(3);
  return true;
}();

}  // namespace
