// rrg fuse: TSDF fusion (core/tsdf) of a posed RGB-D dataset with its ground-truth poses, then a
// marching-cubes mesh as PLY and optionally the volume file. Ctrl-C stops after the frame in
// progress and still writes the mesh (and volume) of the frames fused, then exits 128 + signal.
#include "client/commands/command.h"
#include "client/commands/stop_on_signal.h"
#include "core/common/device.h"
#include "core/io/dataset.h"
#include "core/io/ply.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_io.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

namespace rrg::cli {
namespace {

struct FuseOptions {
  std::string dataset, out, save, device = "auto";
  io::DatasetFlags flags;
  float voxel = 0.01f, trunc = 0.0f, max_depth = 10.0f, stream_radius = 0.0f, band_sigmas = TsdfParams{}.band_sigmas;
  int every = 1, max_frames = 0;
  bool raycast = false;
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

void run_fuse(const FuseOptions& o) {
  if (o.every < 1) throw std::invalid_argument("fuse: --every must be >= 1");
  const Device device = parse_device(o.device);
  const auto dataset = io::open_dataset(o.dataset, o.flags.to_options());
  if (!dataset->has_ground_truth()) throw std::runtime_error("fuse: " + o.dataset + " has no ground-truth poses");
  TsdfParams params;
  params.voxel_size = o.voxel;
  params.truncation = o.trunc > 0.0f ? o.trunc : 4.0f * o.voxel;
  params.band_sigmas = o.band_sigmas;
  params.max_depth = o.max_depth;
  TsdfVolume volume(params, device);
  const Intrinsics& K = dataset->intrinsics();
  spdlog::info("fuse: {} ({} frames, {}x{}) on {}, {}", o.dataset, dataset->size(), K.width, K.height,
               device.to_string(), params.to_string());

  if (const float reach = view_reach(K, params); o.stream_radius > 0.0f && o.stream_radius < reach)
    spdlog::warn("fuse: --stream-radius {:.2f} m is less than the {:.2f} m a frame reaches (max depth {:.2f} m along "
                 "the image corners' rays, plus the band): blocks in view will be streamed out after every frame and "
                 "back with the next; use at least {:.2f} m",
                 o.stream_radius, reach, params.max_depth, reach);
  double t_load = 0, t_fuse = 0, t_raycast = 0, t_stream = 0;
  size_t fused = 0, skipped = 0;
  int64_t peak_resident = 0;  // most blocks resident at once (right after a frame's fusion)
  const StopOnSignal signals;
  bool interrupted = false;
  for (size_t i = 0; i < dataset->size(); i += size_t(o.every)) {
    if (o.max_frames > 0 && fused >= size_t(o.max_frames)) break;
    if (signals.signal() != 0) {
      spdlog::warn("fuse: stopped before frame {} of {}; writing the mesh of the {} frames fused", i, dataset->size(), fused);
      interrupted = true;
      break;
    }
    auto t0 = Clock::now();
    const io::Frame frame = dataset->load(i);
    const auto depth = DeviceImage<float>::from_host(frame.depth, device);
    const auto color = DeviceImage<Color>::from_host(frame.color, device);
    t_load += ms_since(t0);
    if (!frame.T_wc_gt) {
      ++skipped;
      continue;
    }
    const Eigen::Isometry3f T_wc = frame.T_wc_gt->cast<float>();
    t0 = Clock::now();
    integrate(volume, depth, color, K, T_wc);
    t_fuse += ms_since(t0);
    if (o.raycast) {
      t0 = Clock::now();
      const RaycastResult r = raycast(volume, K, T_wc);
      t_raycast += ms_since(t0);
    }
    peak_resident = std::max(peak_resident, volume.num_blocks());
    if (o.stream_radius > 0.0f) {
      t0 = Clock::now();
      volume.stream_out(T_wc.translation(), o.stream_radius);
      t_stream += ms_since(t0);
    }
    ++fused;
    if (fused % 10 == 0)
      spdlog::info("fuse: {} frames fused (frame {}), {} blocks on {}, {} in host memory", fused, i,
                   volume.num_blocks(), device.to_string(), volume.num_host_blocks());
  }
  if (fused == 0) throw std::runtime_error("fuse: no frame with a pose was fused");
  if (skipped > 0) spdlog::warn("fuse: {} frames without a pose skipped", skipped);

  // With streaming the map may not fit the device at once: mesh it in slabs of no more blocks than
  // fusion held resident (the same mesh as meshing it whole).
  auto t0 = Clock::now();
  const TriangleMesh mesh = extract_mesh_streamed(volume, std::max<int64_t>(peak_resident, 1));
  const double t_extract = ms_since(t0);
  if (mesh.triangles.empty()) throw std::runtime_error("fuse: the mesh is empty (no surface in the volume)");
  t0 = Clock::now();
  io::write_ply_mesh(o.out, mesh);
  const double t_write = ms_since(t0);
  if (!o.save.empty()) save_volume(volume, o.save);

  const MemoryUsage mem = volume.memory();
  std::printf("fused %zu frames into %lld blocks (%.1f MB on %s)\n", fused,
              (long long)(volume.num_blocks() + volume.num_host_blocks()), double(mem.device_bytes) / 1e6,
              device.to_string().c_str());
  if (o.stream_radius > 0.0f)
    std::printf("streaming (radius %.2f m): at most %lld blocks resident, %lld in host memory at the end (%.1f MB)\n",
                o.stream_radius, (long long)peak_resident, (long long)volume.num_host_blocks(),
                double(mem.host_bytes) / 1e6);
  std::printf("mesh: %zu vertices, %zu triangles -> %s\n", mesh.vertices.size(), mesh.triangles.size(), o.out.c_str());
  std::printf("timing: load %.2f ms/frame, fusion %.2f ms/frame", t_load / double(fused), t_fuse / double(fused));
  if (o.raycast) std::printf(", raycast %.2f ms/frame", t_raycast / double(fused));
  if (o.stream_radius > 0.0f) std::printf(", streaming %.2f ms/frame", t_stream / double(fused));
  std::printf(", extraction %.1f ms, ply write %.1f ms\n", t_extract, t_write);
  if (interrupted) signals.finish_interrupted(fused);
}

}  // namespace

void register_fuse_command(CLI::App& app) {
  auto opts = std::make_shared<FuseOptions>();
  auto* cmd = app.add_subcommand("fuse", "TSDF fusion of a dataset with its ground-truth poses -> mesh (PLY)");
  cmd->add_option("dataset", opts->dataset, "dataset folder (TUM, 7-Scenes, Replica, synth)")->required();
  cmd->add_option("--out", opts->out, "output mesh (PLY)")->required();
  cmd->add_option("--voxel", opts->voxel, "voxel size s, metres")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--trunc", opts->trunc, "truncation ε, metres (default 4 × voxel)")->check(CLI::PositiveNumber);
  cmd->add_option("--band-sigmas", opts->band_sigmas,
                  "k of the truncation band max(ε, k σ_n(d)) with Kinect v1's σ_n (0: ε at every depth)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-depth", opts->max_depth, "ignore depth beyond this, metres")->capture_default_str();
  cmd->add_option("--device", opts->device, "cpu | cuda | cuda:N | auto")->capture_default_str();
  cmd->add_option("--every", opts->every, "fuse every N-th frame")->capture_default_str();
  cmd->add_option("--max-frames", opts->max_frames, "stop after N fused frames (0 = all)")->capture_default_str();
  cmd->add_option("--save", opts->save, "also write the volume (.tsdf)");
  cmd->add_option("--stream-radius", opts->stream_radius,
                  "move blocks farther than R metres from the camera to host memory after each frame (0 = off); "
                  "the mesh is then made in slabs that fit the device")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--raycast", opts->raycast, "raycast every fused frame from its pose (timing)");
  io::add_dataset_flags(*cmd, opts->flags);
  cmd->callback([opts] { run_fuse(*opts); });
}

}  // namespace rrg::cli
