#pragma once
// The offline runner behind `rrg run` (paper §5's protocol): feeds a dataset through a Session,
// then writes and scores everything a user and the paper's tables need:
//   trajectory.txt (TUM), mesh.ply + mesh.drc, Gaussians (PLY + SPZ, base and reflection),
//   renders of held-out views and of --render-poses, decomposition images (C_b, R, R·C_r, C, GT),
//   timings.json, metrics.json (ATE; PSNR/SSIM on training and held-out views; PSNR on reflective
//   pixels; geometry accuracy/completion against a ground-truth mesh), config.yaml.
#include "core/io/dataset.h"
#include "core/slam/session.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rrg {

struct RunOptions {
  std::filesystem::path dataset;
  io::DatasetOptions dataset_options;
  std::filesystem::path out;                 // empty: nothing written (tests)
  SessionConfig config;                      // K is taken from the dataset
  std::string semantics = "auto";            // auto: labels when the dataset has label images, else none
  size_t max_frames = 0;                     // 0 = all
  double rate_hz = 0;                        // frame i is fed no earlier than i / rate_hz after the start,
                                             // as a sensor streams; 0 = as fast as frames load
  size_t train_stride = 10;                  // every N-th frame is scored as a training view
  std::vector<size_t> decomposition_frames;  // frames whose C_b, R, R·C_r, C and GT images are written
  std::filesystem::path render_poses;        // file of poses to render at the end
  bool write_gaussians = true, write_mesh = true, write_renders = true;
  bool progress = true;                      // progress bar with live FPS on stderr
  // Asked after every frame (e.g. "was Ctrl-C pressed?"); when it returns true the run stops there
  // and finishes as if the dataset ended: every output and metric over the frames processed, and
  // RunMetrics::interrupted set.
  std::function<bool()> stop;
};

// A dataset frame as a session frame: index, timestamp, colour and depth (no labels, no pose).
SessionFrame to_session_frame(io::Frame&& frame);

// One named pose to render: "name tx ty tz qx qy qz qw", or a TUM line (the name is then the
// line's index, 6 digits). Throws std::runtime_error naming the file and line.
struct NamedPose {
  std::string name;
  Eigen::Isometry3f T_wc;
};
std::vector<NamedPose> read_render_poses(const std::filesystem::path& file);

// PSNR over the pixels of one ground-truth reflective plane (synthetic planes.json), pooled over
// the views that see it: the mirror alone, say, where the reflective mask also pools a glossy floor.
struct PlaneScore {
  int id = 0;
  std::string name;
  size_t pixels = 0;
  double psnr = 0;
};

struct ImageScores {
  size_t views = 0;
  double psnr = 0, ssim = 0;          // means over views
  double psnr_reflective = 0;         // PSNR over the pooled reflective pixels (ground-truth mask)
  size_t reflective_pixels = 0;
  std::vector<PlaneScore> reflective_planes;  // per ground-truth reflective plane seen, by id
};

struct RunMetrics {
  size_t frames = 0, lost = 0;                // frames processed (fewer than asked for when interrupted)
  bool interrupted = false;                   // RunOptions::stop ended the run early
  std::optional<double> ate_rmse_cm;          // rigid SE(3) Umeyama alignment
  ImageScores train, held_out;                // held_out only with a novel/ folder (synth)
  // With a ground-truth mesh: accuracy; completion and its ratio (< 3 cm) over the part of the
  // ground-truth surface the input frames observed (eval/observed_surface.h); completion over the
  // whole mesh; the observed fraction of its area.
  std::optional<double> accuracy_cm, completion_cm, completion_ratio, completion_whole_cm, observed_fraction;
  double wall_s = 0, fps = 0;                 // whole run, frames / wall time (loading included)
  int64_t base_gaussians = 0, reflection_gaussians = 0, reflective_planes = 0;
  // Depth filled on reflective masks (planes.fill): frames with a fill, and pixels in all.
  int64_t filled_frames = 0, filled_pixels = 0;
  // The TSDF at the end: blocks in all and resident on the device (fewer with tsdf.stream_radius),
  // the device bytes (the pool's capacity: the most it held) and the host bytes of streamed-out blocks.
  int64_t tsdf_blocks = 0, tsdf_resident_blocks = 0;
  size_t tsdf_device_bytes = 0, tsdf_host_bytes = 0;
};

struct RunTimings {
  StageTimes mean;                 // per frame, over frames
  double mapping_step_ms = 0;      // per mapping step (on the mapping thread unless sync)
  // Its stages per step: keyframe raycasts, densification, optimisation, pruning.
  double mapping_raycast_ms = 0, mapping_densify_ms = 0, mapping_optimise_ms = 0, mapping_prune_ms = 0;
  OptimiseTimes mapping_optimise;  // mapping_optimise_ms by part, per step
  int64_t mapping_steps = 0;
  int64_t mapping_iterations = 0;  // Adam iterations over all steps (live: scaled per step)
  int64_t mapping_waits = 0;       // steps that waited for the one before (MappingSummary::waits)
  std::string schedule;            // sync, overlapped or live (mapping_schedule.h)
  double rate_hz = 0;              // RunOptions::rate_hz (0: frames fed as fast as they load)
  double latency_mean_ms = 0, latency_max_ms = 0;  // with rate_hz > 0: a frame's arrival to process() returning
  double load_ms = 0;              // dataset reading and decoding, per frame (on the loader threads)
  double load_wait_ms = 0;         // what the frame loop waited for a loaded frame, per frame
  double premapping_ms = 0;        // raycast + preprocess + icp + orb + fuse + identify, per frame
  double wall_ms_per_frame = 0;
};

struct RunResult {
  RunMetrics metrics;
  RunTimings timings;
  io::Trajectory trajectory;
};

// Runs the whole pipeline. `progress_line` (optional) receives a line now and then for logs.
RunResult run_dataset(const RunOptions& options);

// metrics.json / timings.json bodies (also printed by `rrg run`).
std::string metrics_json(const RunMetrics& m);
std::string timings_json(const RunTimings& t, const std::string& device);

}  // namespace rrg
