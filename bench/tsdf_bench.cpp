// TSDF fusion, raycast and mesh extraction (paper §4.1.4) per frame on a synthetic living_room
// sequence (rendered once per resolution by core/synth into a temporary folder), at the paper's
// defaults (ε = 2 cm) with voxels of 0.5 cm (the paper's) and 1 cm, on every available device.
// Frames are on the device already. Names: tsdf_<stage>_<w>x<h>/<voxel mm>mm/<device>.
#include "core/io/dataset.h"
#include "core/synth/sequence.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <memory>
#include <unistd.h>

namespace {

constexpr int kFrames = 8;

struct Sequence {
  rrg::Intrinsics K;
  std::vector<rrg::io::Frame> frames;
};

const Sequence& sequence(int width, int height) {
  static std::map<std::pair<int, int>, std::unique_ptr<Sequence>> cache;
  auto& s = cache[{width, height}];
  if (!s) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("rrg-tsdf-bench-" + std::to_string(getpid()) + "-" + std::to_string(width));
    rrg::synth::SynthParams p;
    p.preset = "living_room";
    p.out = dir;
    p.frames = kFrames;
    p.width = width;
    p.height = height;
    p.novel = 1;
    p.write_mesh = false;
    p.overwrite = true;
    rrg::synth::generate_sequence(p);
    const auto dataset = rrg::io::open_dataset(dir);
    s = std::make_unique<Sequence>();
    s->K = dataset->intrinsics();
    for (int i = 0; i < kFrames; ++i) s->frames.push_back(dataset->load(size_t(i)));
    std::filesystem::remove_all(dir);
  }
  return *s;
}

struct DeviceFrames {
  std::vector<rrg::DeviceImage<float>> depth;
  std::vector<rrg::DeviceImage<rrg::Color>> color;
  std::vector<Eigen::Isometry3f> poses;
};

DeviceFrames upload(const Sequence& s, const rrg::Device& device) {
  DeviceFrames f;
  for (const auto& fr : s.frames) {
    f.depth.push_back(rrg::DeviceImage<float>::from_host(fr.depth, device));
    f.color.push_back(rrg::DeviceImage<rrg::Color>::from_host(fr.color, device));
    f.poses.push_back(fr.T_wc_gt->cast<float>());
  }
  return f;
}

rrg::TsdfParams params(float voxel) {
  rrg::TsdfParams p;
  p.voxel_size = voxel;
  return p;
}

void BM_Fuse(benchmark::State& state, rrg::Device device, int w, int h, float voxel) {
  const Sequence& s = sequence(w, h);
  const DeviceFrames f = upload(s, device);
  rrg::TsdfVolume volume(params(voxel), device);
  size_t i = 0, blocks = 0;
  for (auto _ : state) {
    blocks = size_t(rrg::integrate(volume, f.depth[i % kFrames], f.color[i % kFrames], s.K, f.poses[i % kFrames]));
    ++i;
  }
  state.counters["blocks/frame"] = double(blocks);
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

rrg::TsdfVolume fused_volume(const Sequence& s, const DeviceFrames& f, const rrg::Device& device, float voxel) {
  rrg::TsdfVolume volume(params(voxel), device);
  for (int i = 0; i < kFrames; ++i) rrg::integrate(volume, f.depth[size_t(i)], f.color[size_t(i)], s.K, f.poses[size_t(i)]);
  return volume;
}

void BM_Raycast(benchmark::State& state, rrg::Device device, int w, int h, float voxel) {
  const Sequence& s = sequence(w, h);
  const DeviceFrames f = upload(s, device);
  const rrg::TsdfVolume volume = fused_volume(s, f, device, voxel);
  // Into one result, as tracking and the Open3D comparison do: the march and shading, not the
  // first touch of ~60 MB of new images per call at 1280x720.
  rrg::RaycastResult r;
  size_t i = 0;
  for (auto _ : state) {
    rrg::raycast_into(r, volume, s.K, f.poses[i++ % kFrames]);
    benchmark::DoNotOptimize(r.depth.buffer().data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_Extract(benchmark::State& state, rrg::Device device, int w, int h, float voxel) {
  const Sequence& s = sequence(w, h);
  const DeviceFrames f = upload(s, device);
  const rrg::TsdfVolume volume = fused_volume(s, f, device, voxel);
  size_t triangles = 0;
  for (auto _ : state) triangles = rrg::extract_mesh(volume).triangles.size();
  state.counters["triangles"] = double(triangles);
  state.counters["blocks"] = double(volume.num_blocks());
}

const bool registered = [] {
  for (const rrg::Device& device : rrg::available_devices())
    for (auto [w, h] : {std::pair{320, 240}, std::pair{640, 480}, std::pair{1280, 720}})
      for (const int voxel_mm : {5, 10}) {
        const std::string tag = std::to_string(w) + "x" + std::to_string(h) + "/" +
                                std::to_string(voxel_mm) + "mm/" + device.to_string();
        const float voxel = float(voxel_mm) * 1e-3f;
        benchmark::RegisterBenchmark(("tsdf_fuse_" + tag).c_str(), BM_Fuse, device, w, h, voxel)
            ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
        benchmark::RegisterBenchmark(("tsdf_raycast_" + tag).c_str(), BM_Raycast, device, w, h, voxel)
            ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
        benchmark::RegisterBenchmark(("tsdf_extract_" + tag).c_str(), BM_Extract, device, w, h, voxel)
            ->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
      }
  return true;
}();

}  // namespace
