// rrg run: the whole RRG-SLAM pipeline (core/slam Session) on a dataset, with evaluation
// (core/slam/runner.h). --ablate-reflections runs the same frames a second time with base
// Gaussians only and prints both side by side (the paper's reflection ablation, in one run).
// The first Ctrl-C (or SIGTERM) stops the run after the current frame and still writes every output
// over the frames processed (metrics.json "interrupted": true, exit code 128 + the signal: 130 for
// Ctrl-C); a second one aborts.
#include "client/commands/command.h"
#include "client/commands/stop_on_signal.h"
#include "core/common/device.h"
#include "core/io/atomic_file.h"
#include "core/slam/runner.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace rrg::cli {
namespace {

struct RunCliOptions {
  std::string dataset, out, device = "auto", config, tracking, semantics = "auto", render_poses, remote;
  io::DatasetFlags flags;
  std::vector<std::string> overrides;
  std::vector<size_t> decomposition;
  size_t max_frames = 0, train_stride = 10;
  double rate = 0;
  bool no_reflections = false, gt_poses = false, sync = false, live = false, ablate = false, no_progress = false;
};

std::string opt_cm(const std::optional<double>& v) { return v ? fmt::format("{:.2f}", *v) : std::string("-"); }

void print_table(const std::vector<std::pair<std::string, RunResult>>& runs) {
  std::printf("%-16s %8s %10s %10s %8s %11s %12s %9s %9s %7s %8s %8s\n", "run", "ATE cm", "train dB", "novel dB",
              "SSIM", "novel refl", "train refl", "acc cm", "comp cm", "FPS", "G_b", "G_r");
  for (const auto& [name, r] : runs) {
    const RunMetrics& m = r.metrics;
    std::printf("%-16s %8s %10.2f %10.2f %8.4f %11.2f %12.2f %9s %9s %7.2f %8lld %8lld\n", name.c_str(),
                opt_cm(m.ate_rmse_cm).c_str(), m.train.psnr, m.held_out.psnr, m.held_out.views ? m.held_out.ssim : m.train.ssim,
                m.held_out.psnr_reflective, m.train.psnr_reflective, opt_cm(m.accuracy_cm).c_str(),
                opt_cm(m.completion_cm).c_str(), m.fps, (long long)m.base_gaussians, (long long)m.reflection_gaussians);
  }
}

// Held-out PSNR of each ground-truth reflective plane scored in both runs (same names, same pixels).
struct PlaneDelta {
  std::string name;
  double with = 0, without = 0;
};
std::vector<PlaneDelta> reflective_plane_deltas(const ImageScores& with, const ImageScores& without) {
  std::vector<PlaneDelta> out;
  for (const PlaneScore& a : with.reflective_planes)
    for (const PlaneScore& b : without.reflective_planes)
      if (a.id == b.id && a.pixels == b.pixels) out.push_back({a.name, a.psnr, b.psnr});
  return out;
}

void print_timings(const RunTimings& t, const std::string& device) {
  const OptimiseTimes& o = t.mapping_optimise;
  std::printf("timing (%s, ms/frame): load %.2f (ahead; waited %.2f) | raycast %.2f preprocess %.2f icp %.2f"
              " orb %.2f (mask %.2f) fuse %.2f (stream %.2f) identify %.2f = pre-mapping %.2f | mapping %.2f ms/step (raycast %.1f"
              " densify %.1f optimise %.1f [render %.1f loss %.1f backward %.1f adam %.1f] prune %.1f) x %lld steps"
              " (%lld iterations; %s, %lld waited for the one before; %.2f ms/frame waited or inline) | wall %.2f ms/frame (%.2f FPS%s)\n",
              device.c_str(), t.load_ms, t.load_wait_ms, t.mean.raycast, t.mean.preprocess, t.mean.icp, t.mean.orb,
              t.mean.mask, t.mean.fuse, t.mean.stream, t.mean.identify, t.premapping_ms, t.mapping_step_ms, t.mapping_raycast_ms,
              t.mapping_densify_ms, t.mapping_optimise_ms, o.render, o.loss, o.backward, o.adam, t.mapping_prune_ms,
              (long long)t.mapping_steps, (long long)t.mapping_iterations, t.schedule.c_str(), (long long)t.mapping_waits, t.mean.mapping, t.wall_ms_per_frame,
              t.wall_ms_per_frame > 0 ? 1000.0 / t.wall_ms_per_frame : 0.0,
              t.rate_hz > 0 ? fmt::format("; input at most {:g} Hz, latency mean {:.1f} max {:.1f} ms", t.rate_hz,
                                           t.latency_mean_ms, t.latency_max_ms).c_str()
                            : "");
}

void print_tsdf(const RunMetrics& m) {
  std::printf("tsdf: %lld blocks, %lld resident at the end; device %.1f MB (the pool: the most it held), host %.1f MB\n",
              (long long)m.tsdf_blocks, (long long)m.tsdf_resident_blocks, double(m.tsdf_device_bytes) / 1e6,
              double(m.tsdf_host_bytes) / 1e6);
}

void run(const RunCliOptions& o) {
  RunOptions ro;
  ro.dataset = o.dataset;
  ro.dataset_options = o.flags.to_options();
  ro.out = o.out;
  SessionConfig& c = ro.config;
  c.device = parse_device(o.device);
  if (!o.config.empty()) load_config_yaml(c, o.config);
  for (const std::string& s : o.overrides) apply_override(c, s);
  if (!o.tracking.empty()) c.tracking.mode = parse_tracking_mode(o.tracking);
  if (o.no_reflections) c.mapping.reflections = false;
  if (o.gt_poses) c.gt_poses = true;
  if (o.sync) c.sync = true;
  if (o.live) c.live = true;
  if (!o.remote.empty()) c.remote_address = o.remote;
  ro.semantics = o.semantics;
  ro.max_frames = o.max_frames;
  ro.rate_hz = o.rate;
  ro.train_stride = o.train_stride;
  ro.decomposition_frames = o.decomposition;
  ro.render_poses = o.render_poses;
  ro.progress = !o.no_progress;
  StopOnSignal signals;
  ro.stop = [&signals] { return signals.signal() != 0; };

  std::vector<std::pair<std::string, RunResult>> runs;
  runs.emplace_back(c.mapping.reflections ? "reflections" : "no-reflections", run_dataset(ro));
  print_timings(runs.back().second.timings, c.device.to_string());
  print_tsdf(runs.back().second.metrics);
  const bool interrupted = runs.back().second.metrics.interrupted;
  if (interrupted && o.ablate) spdlog::warn("run: interrupted, so the --no-reflections run of the ablation is skipped");
  if (o.ablate && c.mapping.reflections && !interrupted) {
    RunOptions base = ro;
    base.config.mapping.reflections = false;
    base.out = o.out.empty() ? std::filesystem::path() : std::filesystem::path(o.out) / "no_reflections";
    base.decomposition_frames.clear();
    runs.emplace_back("no-reflections", run_dataset(base));
    print_timings(runs.back().second.timings, c.device.to_string());
  }
  const bool second_interrupted = runs.size() == 2 && runs[1].second.metrics.interrupted;
  if (second_interrupted) spdlog::warn("run: the --no-reflections run was interrupted; no comparison is written");
  print_table(runs);
  if (runs.size() == 2 && !second_interrupted) {
    const RunMetrics &a = runs[0].second.metrics, &b = runs[1].second.metrics;
    std::printf("reflections - no-reflections: novel reflective %+.2f dB, novel %+.2f dB, train reflective %+.2f dB, ATE %+.3f cm\n",
                a.held_out.psnr_reflective - b.held_out.psnr_reflective, a.held_out.psnr - b.held_out.psnr,
                a.train.psnr_reflective - b.train.psnr_reflective,
                (a.ate_rmse_cm && b.ate_rmse_cm) ? *a.ate_rmse_cm - *b.ate_rmse_cm : 0.0);
    const auto plane_deltas = reflective_plane_deltas(a.held_out, b.held_out);
    if (!plane_deltas.empty()) {
      std::printf("held-out views by ground-truth reflective plane (reflections vs no-reflections):");
      for (const PlaneDelta& d : plane_deltas)
        std::printf(" %s %.2f vs %.2f dB (%+.2f)%s", d.name.c_str(), d.with, d.without, d.with - d.without,
                    &d == &plane_deltas.back() ? "" : ",");
      std::printf("\n");
    }
    if (!o.out.empty())
      io::write_atomically(std::filesystem::path(o.out) / "ablation.json", [&](const std::filesystem::path& tmp) {
        nlohmann::ordered_json j;
        j["reflections"] = nlohmann::json::parse(metrics_json(a));
        j["no_reflections"] = nlohmann::json::parse(metrics_json(b));
        j["delta_psnr_reflective_held_out_db"] = a.held_out.psnr_reflective - b.held_out.psnr_reflective;
        j["delta_psnr_held_out_db"] = a.held_out.psnr - b.held_out.psnr;
        for (const PlaneDelta& d : plane_deltas) j["delta_psnr_held_out_by_reflective_plane_db"][d.name] = d.with - d.without;
        std::ofstream(tmp) << j.dump(2) << "\n";
      });
  }
  if (!o.out.empty()) std::printf("outputs -> %s (trajectory.txt, mesh.ply/.drc, gaussians_*.ply/.spz, renders/, metrics.json, timings.json)\n", o.out.c_str());
  if (runs.back().second.metrics.interrupted) {
    signals.finish_interrupted(runs.back().second.metrics.frames);
  }
}

}  // namespace

void register_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCliOptions>();
  auto* cmd = app.add_subcommand("run", "the whole pipeline on a dataset: track, fuse, identify planes, optimise Gaussians; "
                                        "writes trajectory, mesh, Gaussians, renders, metrics");
  cmd->add_option("dataset,--dataset", o->dataset, "dataset folder (TUM, 7-Scenes, Replica, synth)")->required();
  cmd->add_option("--out", o->out, "output folder (created)");
  cmd->add_option("--device", o->device, "cpu | cuda | cuda:N | auto")->capture_default_str();
  cmd->add_option("--config", o->config, "YAML config file (nested keys as listed by --set)")->check(CLI::ExistingFile);
  cmd->add_option("--set", o->overrides, "override a config value, key=value (e.g. tsdf.voxel_size=0.01); repeatable");
  cmd->add_option("--tracking", o->tracking, "icp | icp+orb | icp+orb+mask (default: the config's, icp+orb+mask)")
      ->check(CLI::IsMember({"icp", "icp+orb", "icp+orb+mask"}));
  cmd->add_option("--semantics", o->semantics, "auto | none | labels | remote")->capture_default_str()
      ->check(CLI::IsMember({"auto", "none", "labels", "remote"}));
  cmd->add_option("--remote", o->remote, "segmenter address for --semantics remote (host:port)");
  cmd->add_flag("--no-reflections", o->no_reflections, "base Gaussians only (the GPS-SLAM-like baseline)");
  cmd->add_flag("--ablate-reflections", o->ablate, "also run with --no-reflections on the same frames; print both");
  cmd->add_flag("--gt-poses", o->gt_poses, "use the dataset's ground-truth poses (mapping only)");
  cmd->add_flag("--sync", o->sync, "deterministic: mapping steps inline at the same frame positions");
  cmd->add_flag("--live", o->live, "pre-mapping never waits for a running mapping step (fewer steps where mapping is slower)")
      ->excludes("--sync");
  cmd->add_option("--max-frames", o->max_frames, "stop after N frames (0 = all)")->capture_default_str();
  cmd->add_option("--rate", o->rate, "feed frames at most this many per second, as a sensor streams (0 = as fast as they load)")
      ->capture_default_str();
  cmd->add_option("--train-stride", o->train_stride, "score every N-th frame as a training view (0 = none)")
      ->capture_default_str();
  cmd->add_option("--decomposition", o->decomposition, "frames whose C_b, R, R*C_r, C and ground truth are written")
      ->delimiter(',');
  cmd->add_option("--render-poses", o->render_poses, "file of 'name tx ty tz qx qy qz qw' (or TUM) lines to render at the end")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--no-progress", o->no_progress, "no progress bar");
  io::add_dataset_flags(*cmd, o->flags);
  cmd->callback([o] { run(*o); });
}

}  // namespace rrg::cli
