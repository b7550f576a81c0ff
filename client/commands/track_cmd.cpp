// rrg track: reflection-aware tracking (core/tracking) + TSDF fusion (core/tsdf) on a dataset,
// without the rest of the pipeline: each frame is tracked against the raycast of the volume at the
// previous pose, then fused at its tracked pose. Writes the trajectory (TUM) and prints per-stage
// milliseconds, the tracking states and, when the dataset has ground truth, the ATE.
#include "client/commands/command.h"
#include "client/commands/stop_on_signal.h"
#include "core/common/device.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/atomic_file.h"
#include "core/io/dataset.h"
#include "core/io/ply.h"
#include "core/io/trajectory.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/model_source.h"
#include "core/tracking/tracker.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

namespace rrg::cli {
namespace {

struct TrackOptions {
  std::string dataset, out, mode = "icp+orb+mask", mask = "auto", device = "auto", log, mesh;
  io::DatasetFlags flags;
  float voxel = 0.01f, trunc = 0.0f, max_depth = 5.0f, band_sigmas = TsdfParams{}.band_sigmas;
  int max_frames = 0, progress = 50;
  bool no_bilateral = false, identity_start = false, fuse_raw = false, no_noise_weighting = false;
  float icp_prior = TrackingParams{}.orb.icp_prior_scale;
  float orb_depth_range = TrackingParams{}.orb.max_depth_range;
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::unique_ptr<MaskSource> make_mask_source(const TrackOptions& o, const io::Dataset& dataset, TrackingMode mode) {
  if (o.mask != "auto" && o.mask != "synth" && o.mask != "none")
    throw std::invalid_argument("track: --mask must be auto, synth or none (got '" + o.mask + "')");
  if (mode != TrackingMode::IcpOrbMask) return nullptr;
  if (o.mask == "none")
    throw std::invalid_argument("track: --tracking icp+orb+mask needs a mask source (--mask synth)");
  if (dataset.format() != io::DatasetFormat::Synth)
    throw std::runtime_error("track: --tracking icp+orb+mask needs tracking masks; the only source before the "
                             "Gaussian engine is a synthetic dataset's reflection/ masks, and " + o.dataset +
                             " is " + io::to_string(dataset.format()) + " (use --tracking icp or icp+orb)");
  return std::make_unique<SynthReflectionMasks>(dataset.root());
}

void run_track(const TrackOptions& o) {
  TrackingParams params;
  params.mode = parse_tracking_mode(o.mode);
  params.preprocess.bilateral = !o.no_bilateral;
  params.icp.noise_weighting = !o.no_noise_weighting;
  params.orb.icp_prior_scale = o.icp_prior;
  params.orb.max_depth_range = o.orb_depth_range;
  const Device device = parse_device(o.device);
  const auto dataset = io::open_dataset(o.dataset, o.flags.to_options());
  const auto masks = make_mask_source(o, *dataset, params.mode);
  const Intrinsics& K = dataset->intrinsics();
  TsdfParams tsdf;
  tsdf.voxel_size = o.voxel;
  tsdf.truncation = o.trunc > 0.0f ? o.trunc : 4.0f * o.voxel;
  tsdf.band_sigmas = o.band_sigmas;
  tsdf.noise = params.icp.noise;  // one sensor
  tsdf.max_depth = o.max_depth;
  TsdfVolume volume(tsdf, device);
  TsdfModelSource model(volume, K);
  Tracker tracker(params, K, device);
  size_t n = o.max_frames > 0 ? std::min(dataset->size(), size_t(o.max_frames)) : dataset->size();
  const StopOnSignal signals;  // Ctrl-C: stop after the current frame, still write the trajectory
  bool interrupted = false;
  spdlog::info("track: {} ({} frames, {}x{}) on {}, tracking {}, {}", o.dataset, n, K.width, K.height,
               device.to_string(), to_string(params.mode), tsdf.to_string());

  io::Trajectory trajectory;
  std::string log = "frame,timestamp,state,icp_agreement,icp_inlier_ratio,icp_rmse_mm,icp_iterations,orb_keypoints,orb_matches,"
                    "orb_inliers,orb_refined,relocalised,keyframe,ms_raycast,ms_preprocess,ms_icp,ms_orb,ms_fuse,note\n";
  double t_load = 0, t_raycast = 0, t_pre = 0, t_icp = 0, t_orb = 0, t_fuse = 0;
  size_t counts[3] = {0, 0, 0}, refined = 0, relocalised = 0, tracked = 0;
  Eigen::Isometry3f T_last = Eigen::Isometry3f::Identity();
  const auto wall0 = Clock::now();
  for (size_t i = 0; i < n; ++i) {
    auto t0 = Clock::now();
    const io::Frame frame = dataset->load(i);
    const auto depth = DeviceImage<float>::from_host(frame.depth, device);
    const auto color = DeviceImage<Color>::from_host(frame.color, device);
    t_load += ms_since(t0);
    if (i == 0 && frame.T_wc_gt && !o.identity_start) tracker.set_initial_pose(frame.T_wc_gt->cast<float>());
    double ms_raycast = 0;
    if (i > 0) {  // the model at T_{k−1}, timed here (the tracker then reuses it)
      t0 = Clock::now();
      model.model_at(T_last);
      ms_raycast = ms_since(t0);
    }
    const TrackResult r = tracker.track({i, &frame.color, &frame.depth, &depth}, model, masks.get());
    double ms_fuse = 0;
    if (r.state != TrackingState::Lost) {
      t0 = Clock::now();
      // The sensor's D_k with the filtered depth's normals unless asked otherwise: see Tracker::normal_depth().
      integrate(volume, depth, color, K, r.T_wc, nullptr, o.fuse_raw ? nullptr : tracker.normal_depth());
      model.invalidate();
      ms_fuse = ms_since(t0);
    }
    T_last = r.T_wc;
    trajectory.push_back({frame.timestamp, r.T_wc.cast<double>()});
    ++counts[int(r.state)];
    refined += r.orb_refined;
    relocalised += r.relocalised;
    if (!r.first) {
      ++tracked;
      t_raycast += ms_raycast;
      t_pre += r.ms_preprocess;
      t_icp += r.ms_icp;
      t_orb += r.ms_orb;
    }
    t_fuse += ms_fuse;
    if (r.state != TrackingState::Ok || !r.note.empty())
      spdlog::debug("track: frame {}: {} {}", i, to_string(r.state), r.note);
    if (r.state == TrackingState::Lost) spdlog::warn("track: frame {} lost ({})", i, r.note);
    log += fmt::format("{},{:.6f},{},{:.4f},{:.4f},{:.3f},{},{},{},{},{},{},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},\"{}\"\n", i,
                       frame.timestamp, to_string(r.state), r.icp.agreement, r.icp.inlier_ratio, r.icp.rmse_m * 1e3, r.icp.iterations,
                       r.orb_keypoints, r.orb_matches, r.orb_inliers, int(r.orb_refined), int(r.relocalised),
                       int(r.keyframe), ms_raycast, r.ms_preprocess, r.ms_icp, r.ms_orb, ms_fuse, r.note);
    if ((i + 1) % size_t(std::max(1, o.progress)) == 0 || i + 1 == n)
      spdlog::info("track: {}/{} frames, {} ok / {} degraded / {} lost, {} orb-refined, {} keyframes, {:.1f} ms/frame",
                   i + 1, n, counts[0], counts[1], counts[2], refined, tracker.keyframes().size(),
                   ms_since(wall0) / double(i + 1));
    if (i + 1 < n && signals.signal() != 0) {
      spdlog::warn("track: stopped after frame {} of {}; writing the trajectory of those frames", i + 1, n);
      n = i + 1;
      interrupted = true;
    }
  }
  const double wall_ms = ms_since(wall0);
  io::write_tum_trajectory(o.out, trajectory);
  if (!o.log.empty())
    io::write_atomically(o.log, [&](const std::filesystem::path& tmp) {
      std::ofstream f(tmp);
      f << log;
      if (!f) throw std::runtime_error("track: cannot write " + o.log);
    });

  const double per = tracked > 0 ? 1.0 / double(tracked) : 0.0;
  std::printf("tracked %zu frames (%s, %s): %zu ok, %zu degraded, %zu lost; %zu orb-refined, %zu relocalised, "
              "%zu keyframes -> %s\n", n, to_string(params.mode).c_str(), device.to_string().c_str(), counts[0],
              counts[1], counts[2], refined, relocalised, tracker.keyframes().size(), o.out.c_str());
  std::printf("timing (ms/frame): raycast %.2f, preprocess %.2f, icp %.2f, orb+ba %.2f, tracking total %.2f, "
              "fusion %.2f, load %.2f; wall %.1f ms/frame (%.1f FPS)\n", t_raycast * per, t_pre * per, t_icp * per,
              t_orb * per, (t_pre + t_icp + t_orb) * per, t_fuse / double(n), t_load / double(n), wall_ms / double(n),
              1000.0 * double(n) / wall_ms);
  if (dataset->has_ground_truth() && trajectory.size() < eval::kMinAlignedPoses) {
    std::printf("no ATE: %zu pose(s), the alignment needs at least %zu\n", trajectory.size(), eval::kMinAlignedPoses);
  } else if (dataset->has_ground_truth()) {
    const eval::TrajectoryMetrics m = eval::evaluate_trajectory(trajectory, dataset->ground_truth());
    std::printf("ATE RMSE %.3f cm (rigid SE(3) Umeyama alignment, %zu poses; max %.3f cm, unaligned %.3f cm)\n",
                m.ate.rmse_cm, m.ate.matched, m.ate.max_cm, m.ate.rmse_unaligned_cm);
  }
  if (!o.mesh.empty()) {
    const TriangleMesh mesh = extract_mesh(volume);
    io::write_ply_mesh(o.mesh, mesh);
    std::printf("mesh: %zu vertices, %zu triangles -> %s\n", mesh.vertices.size(), mesh.triangles.size(), o.mesh.c_str());
  }
  if (interrupted) {
    signals.finish_interrupted(n);
  }
}

}  // namespace

void register_track_command(CLI::App& app) {
  auto opts = std::make_shared<TrackOptions>();
  auto* cmd = app.add_subcommand("track", "reflection-aware tracking + TSDF fusion on a dataset -> trajectory (TUM)");
  cmd->add_option("dataset,--dataset", opts->dataset, "dataset folder (TUM, 7-Scenes, Replica, synth)")->required();
  cmd->add_option("--out", opts->out, "output trajectory (TUM text)")->required();
  cmd->add_option("--tracking", opts->mode, "icp | icp+orb | icp+orb+mask")
      ->capture_default_str()
      ->check(CLI::IsMember({"icp", "icp+orb", "icp+orb+mask"}));
  cmd->add_option("--mask", opts->mask, "tracking mask source for icp+orb+mask: auto | synth (ground truth)")
      ->capture_default_str();
  cmd->add_option("--device", opts->device, "cpu | cuda | cuda:N | auto")->capture_default_str();
  cmd->add_option("--voxel", opts->voxel, "TSDF voxel size, metres")->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_option("--trunc", opts->trunc, "truncation, metres (default 4 x voxel)")->check(CLI::PositiveNumber);
  cmd->add_option("--band-sigmas", opts->band_sigmas,
                  "k of the truncation band max(ε, k σ_n(d)) with Kinect v1's σ_n (0: ε at every depth)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-depth", opts->max_depth, "ignore depth beyond this, metres")->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-frames", opts->max_frames, "stop after N frames (0 = all)")->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--progress", opts->progress, "progress line every N frames")->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--log", opts->log, "per-frame CSV (state, ICP quality, ORB matches, timings)");
  cmd->add_option("--mesh", opts->mesh, "also write the fused mesh (PLY)");
  cmd->add_option("--icp-prior", opts->icp_prior, "weight s of the ICP pose prior in the ORB bundle adjustment (0 = none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--orb-depth-range", opts->orb_depth_range,
                  "a keypoint whose window's depths span more than this fraction of its depth keeps no depth (0 = off)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-bilateral", opts->no_bilateral, "skip the bilateral depth filter");
  cmd->add_flag("--no-noise-weighting", opts->no_noise_weighting,
                "weigh every ICP pair alike instead of by the sensor's depth noise at its depth (ablation)");
  cmd->add_flag("--fuse-raw-depth", opts->fuse_raw,
                "fuse the raw depth with its own normals instead of the bilateral-filtered depth's (ablation)");
  cmd->add_flag("--identity-start", opts->identity_start, "start at the identity instead of the first ground-truth pose");
  io::add_dataset_flags(*cmd, opts->flags);
  cmd->callback([opts] { run_track(*opts); });
}

}  // namespace rrg::cli
