// Side-by-side TSDF benchmark against Open3D 0.16's t::geometry::VoxelBlockGrid on the CPU (issue
// #3: "faster than Open3D on CPU"). Same synthetic living_room frames (core/synth), same poses,
// voxel size, truncation (Open3D: trunc_voxel_multiplier = ε / s) and block resolution 8. Per
// frame: integration (Open3D: GetUniqueBlockCoordinates + Integrate; ours: integrate(), which also
// allocates); then a raycast of every frame's view (Open3D: every allocated block as the block set,
// attributes depth, vertex, normal, colour; ours: the same maps, RaycastOutputs colour only, and
// once more with every RaycastResult map, reported beside it); then mesh extraction.
// Prints ms per frame, ratios, and how far the two raycast depth maps are apart (a sanity check
// that both compute the same thing). Built only with -DRRG_BENCH_OPEN3D=ON when Open3D is found.
#include "bench/open3d/bench_clock.h"
#include "core/io/dataset.h"
#include "core/synth/sequence.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"

#include <CLI/CLI.hpp>
#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/Image.h>
#include <open3d/t/geometry/TriangleMesh.h>
#include <open3d/t/geometry/VoxelBlockGrid.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <unistd.h>

namespace {

namespace o3c = open3d::core;
constexpr int64_t kBlockCapacity = 40000;
namespace o3g = open3d::t::geometry;

using rrg::bench::Clock;
using rrg::bench::intrinsic_tensor;
using rrg::bench::now;

o3c::Tensor extrinsic_tensor(const Eigen::Isometry3f& T_wc) {  // Open3D wants world -> camera
  const Eigen::Matrix4d T = T_wc.inverse().matrix().cast<double>();
  std::vector<double> v(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v[size_t(4 * r + c)] = T(r, c);
  return o3c::Tensor(v, {4, 4}, o3c::Float64);
}

struct Times {
  Clock ours{0, 0}, open3d{0, 0};
  // Ours ran from a0 to a1, Open3D from b0 to b1.
  void add(const Clock& a0, const Clock& a1, const Clock& b0, const Clock& b1) {
    ours.wall += a1.wall - a0.wall;
    ours.cpu += a1.cpu - a0.cpu;
    open3d.wall += b1.wall - b0.wall;
    open3d.cpu += b1.cpu - b0.cpu;
  }
  void add(const Clock& t0, const Clock& t1, const Clock& t2) { add(t0, t1, t1, t2); }
  void print(const char* what, int n) const {
    std::printf("%-20s %9.2f %9.2f %7.2fx %9.2f %9.2f %7.2fx\n", what, ours.wall / n, open3d.wall / n,
                open3d.wall / std::max(ours.wall, 1e-9), ours.cpu / n, open3d.cpu / n,
                open3d.cpu / std::max(ours.cpu, 1e-9));
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"TSDF: ours vs Open3D VoxelBlockGrid (CPU)"};
  int width = 640, height = 480, frames = 8;
  float voxel = 0.005f, truncation = 0.02f, max_depth = 10.0f, band_sigmas = 0.0f;
  std::string preset = "living_room";
  app.add_option("--width", width);
  app.add_option("--height", height);
  app.add_option("--frames", frames, "frames fused and raycast");
  app.add_option("--voxel", voxel, "voxel size s, metres");
  app.add_option("--trunc", truncation, "truncation ε, metres");
  app.add_option("--max-depth", max_depth, "depth range of fusion and raycast, metres");
  app.add_option("--band-sigmas", band_sigmas,
                 "ours: k of the band max(ε, k σ_n(d)); default 0, Open3D's constant band (like for like)");
  app.add_option("--preset", preset);
  CLI11_PARSE(app, argc, argv);

  const auto dir = std::filesystem::temp_directory_path() / ("rrg-open3d-bench-" + std::to_string(getpid()));
  rrg::synth::SynthParams sp;
  sp.preset = preset;
  sp.out = dir;
  sp.frames = frames;
  sp.width = width;
  sp.height = height;
  sp.novel = 1;
  sp.write_mesh = false;
  sp.overwrite = true;
  rrg::synth::generate_sequence(sp);
  const auto dataset = rrg::io::open_dataset(dir);
  const rrg::Intrinsics K = dataset->intrinsics();
  std::vector<rrg::io::Frame> seq;
  for (int i = 0; i < frames; ++i) seq.push_back(dataset->load(size_t(i)));
  std::filesystem::remove_all(dir);

  const rrg::Device cpu = rrg::Device::cpu();
  rrg::TsdfParams params;
  params.voxel_size = voxel;
  params.truncation = truncation;
  params.max_depth = max_depth;
  params.band_sigmas = band_sigmas;
  params.initial_blocks = kBlockCapacity;  // both start with the same preallocated block pool
  rrg::TsdfVolume ours(params, cpu);
  const float trunc_mult = truncation / voxel;
  const o3c::Device o3d_cpu("CPU:0");
  o3g::VoxelBlockGrid vbg({"tsdf", "weight", "color"}, {o3c::Float32, o3c::Float32, o3c::Float32},
                          {{1}, {1}, {3}}, voxel, 8, kBlockCapacity, o3d_cpu);
  const o3c::Tensor intr = intrinsic_tensor(K);

  std::vector<rrg::DeviceImage<float>> depth;
  std::vector<rrg::DeviceImage<rrg::Color>> color;
  std::vector<o3g::Image> o3d_depth, o3d_color;
  std::vector<Eigen::Isometry3f> poses;
  for (const auto& f : seq) {
    depth.push_back(rrg::DeviceImage<float>::from_host(f.depth, cpu));
    color.push_back(rrg::DeviceImage<rrg::Color>::from_host(f.color, cpu));
    o3d_depth.emplace_back(o3c::Tensor(f.depth.data(), {height, width, 1}, o3c::Float32));
    o3d_color.emplace_back(o3c::Tensor(f.color.data()->data(), {height, width, 3}, o3c::Float32));
    poses.push_back(f.T_wc_gt->cast<float>());
  }

  Times fuse, ray, mesh;
  for (int i = 0; i < frames; ++i) {
    Clock t0 = now();
    rrg::integrate(ours, depth[size_t(i)], color[size_t(i)], K, poses[size_t(i)]);
    Clock t1 = now();
    const o3c::Tensor extr = extrinsic_tensor(poses[size_t(i)]);
    const o3c::Tensor blocks = vbg.GetUniqueBlockCoordinates(o3d_depth[size_t(i)], intr, extr, 1.0f, max_depth, trunc_mult);
    vbg.Integrate(blocks, o3d_depth[size_t(i)], o3d_color[size_t(i)], intr, extr, 1.0f, max_depth, trunc_mult);
    Clock t2 = now();
    fuse.add(t0, t1, t2);
  }
  auto hashmap = vbg.GetHashMap();
  const o3c::Tensor all_blocks = hashmap.GetKeyTensor().IndexGet({hashmap.GetActiveIndices().To(o3c::Int64)});

  Times ray_all;  // ours with the reflection maps too (I, R_raw, R, C_var), against the same Open3D run
  // Ours raycasts into the same images every frame, as the tracking loop does (raycast_into);
  // Open3D's RayCast returns new tensors on every call (its API takes no output).
  rrg::RaycastResult r, r_all;
  double depth_diff = 0;
  int64_t both_hit = 0, hit_ours = 0, hit_open3d = 0;
  for (int i = 0; i < frames; ++i) {
    Clock t0 = now();
    rrg::raycast_into(r, ours, K, poses[size_t(i)], {}, {.color = true, .reflection = false});
    Clock t1 = now();
    auto o = vbg.RayCast(all_blocks, intr, extrinsic_tensor(poses[size_t(i)]), width, height,
                         {"depth", "vertex", "normal", "color"}, 1.0f, params.min_depth, max_depth, 1.0f, trunc_mult, 8);
    Clock t2 = now();
    ray.add(t0, t1, t2);
    rrg::raycast_into(r_all, ours, K, poses[size_t(i)]);
    Clock t3 = now();
    ray_all.add(t2, t3, t1, t2);
    const rrg::DepthImage d = r.depth.to_host();
    const o3c::Tensor od = o.at("depth").Contiguous();
    const float* op = od.GetDataPtr<float>();
    for (size_t p = 0; p < d.size(); ++p) {
      const bool a = d[p] > 0, b = op[p] > 0;
      hit_ours += a;
      hit_open3d += b;
      if (a && b) {
        depth_diff += std::abs(d[p] - op[p]);
        ++both_hit;
      }
    }
  }

  Clock t0 = now();
  const rrg::TriangleMesh m = rrg::extract_mesh(ours);
  Clock t1 = now();
  const o3g::TriangleMesh om = vbg.ExtractTriangleMesh(1.0f);
  Clock t2 = now();
  mesh.add(t0, t1, t2);

  std::printf("%s %dx%d, %d frames, voxel %.1f mm, truncation %.1f cm, blocks ours %lld / Open3D %lld\n",
              preset.c_str(), width, height, frames, voxel * 1e3, truncation * 1e2, (long long)ours.num_blocks(),
              (long long)all_blocks.GetLength());
  std::printf("%-20s %9s %9s %8s %9s %9s %8s\n", "ms", "wall ours", "Open3D", "ratio", "CPU ours",
              "Open3D", "ratio");
  fuse.print("integrate / frame", frames);
  ray.print("raycast / frame", frames);
  ray_all.print("  + reflection maps", frames);
  mesh.print("extract mesh", 1);
  std::printf("mesh triangles: ours %zu, Open3D %lld\n", m.triangles.size(),
              (long long)(om.HasTriangleIndices() ? om.GetTriangleIndices().GetLength() : 0));
  std::printf("raycast hits: ours %lld, Open3D %lld; mean |depth difference| where both hit: %.3f mm\n",
              (long long)hit_ours, (long long)hit_open3d, both_hit ? 1e3 * depth_diff / double(both_hit) : 0.0);
  return 0;
}
