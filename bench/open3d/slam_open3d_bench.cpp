// Side-by-side dense SLAM benchmark against Open3D 0.16's t::pipelines::slam::Model on the CPU
// (issue #4: "Open3D's dense SLAM, frame-to-model ICP: ATE and ms/frame for both"). One run, the
// same frames from any dataset our readers open (core/io), interleaved frame by frame:
//   ours:   the loop of `rrg track` (client/commands/track_cmd.cpp), with the same library calls:
//           TsdfModelSource::model_at(T_{k−1}) (raycast), Tracker::track (preprocess → ICP → ORB),
//           integrate() of the depth with Tracker::normal_depth()'s normals at the tracked pose unless lost;
//   Open3D: the loop of its DenseSLAM example (examples/cpp/DenseSLAM.cpp): SynthesizeModelFrame at
//           T_{k−1} (raycast of the last frame's frustum blocks, no colour), TrackFrameToModel
//           (point-to-plane multi-scale odometry, {6, 3, 1} iterations, depth_diff), the example's
//           failure test (fitness ≥ 0.1, |t| < 15 cm; else keep the pose and do not integrate),
//           UpdateFramePose, Integrate.
//           One substitution: Model::TrackFrameToModel cannot run on the CPU in Debian's build
//           (odometry::RGBDOdometryMultiScalePointToPlane smooths the target depth with
//           Image::FilterBilateral(5, 5, 10), which on the CPU exists only with Intel IPP: "FilterBilateral
//           with data type Float32 on device CPU:0 is not implemented"). track_frame_to_model() below
//           is that function's body with Open3D's public calls (ClipTransform, CreateVertexMap,
//           CreateNormalMap, PyrDownDepth, ComputeOdometryResultPointToPlane, the same early exit) and
//           the 5×5 bilateral filter (σ_value 5 m, σ_space 10 px) as a plain loop that skips invalid
//           neighbours. Its time is counted as Open3D's tracking.
// Both start at the dataset's first ground-truth pose and get the same voxel size, truncation
// (Open3D: trunc_voxel_multiplier = ε / s), depth range and depth images (float metres, scale 1).
// Prints ATE (rigid SE(3) Umeyama, core/eval as `rrg eval ate`), per-stage ms/frame (wall and process
// CPU time) and writes both trajectories (TUM). Built only with -DRRG_BENCH_OPEN3D=ON.
// Diagnostics, off by default and not Open3D's loop: --o3d-round-pixels and --o3d-half-voxel cancel
// two half-cell biases of Open3D 0.16's Integrate and RayCast (see their help, bench/RESULTS.md);
// --o3d-iterations changes its odometry iterations; --open3d-only skips ours; --log writes per-frame
// tracking quality of both.
#include "core/common/device.h"
#include "core/eval/trajectory_metrics.h"
#include "bench/open3d/bench_clock.h"
#include "core/io/dataset.h"
#include "core/io/trajectory.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/model_source.h"
#include "core/tracking/tracker.h"
#include "core/tsdf/tsdf_integrate.h"

#include <CLI/CLI.hpp>
#include <open3d/core/Tensor.h>
#include <open3d/t/geometry/Image.h>
#include <open3d/t/pipelines/odometry/RGBDOdometry.h>
#include <open3d/t/pipelines/slam/Frame.h>
#include <open3d/t/pipelines/slam/Model.h>
#include <open3d/utility/Logging.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

namespace {

namespace o3c = open3d::core;
namespace o3g = open3d::t::geometry;
namespace slam = open3d::t::pipelines::slam;

size_t g_range_map_warnings = 0;  // Open3D's "Could not generate full range map" (see main)

using rrg::bench::Clock;
using rrg::bench::intrinsic_tensor;
using rrg::bench::now;

// Accumulated wall and CPU milliseconds of one stage.
struct Stage {
  double wall = 0, cpu = 0;
  void add(const Clock& t0, const Clock& t1) {
    wall += t1.wall - t0.wall;
    cpu += t1.cpu - t0.cpu;
  }
};

struct Options {
  std::string dataset, out_dir, mode = "icp";
  rrg::io::DatasetFlags flags;
  int frames = 0, progress = 50;
  float voxel = 0.01f, trunc = 0.0f, max_depth = 5.0f, band_sigmas = rrg::TsdfParams{}.band_sigmas;
  int o3d_block_resolution = 16, o3d_block_count = 10000;
  float o3d_depth_diff = 0.07f, o3d_min_fitness = 0.1f, o3d_max_translation = 0.15f;
  std::vector<int> o3d_iterations = {6, 3, 1};  // coarse to fine, TrackFrameToModel's default
  std::string log;                              // per-frame CSV
  bool o3d_round_pixels = false;                // diagnostic, see --o3d-round-pixels
  bool o3d_half_voxel = false;                  // diagnostic, see --o3d-half-voxel
  bool open3d_only = false;                     // skip ours (diagnostic runs of Open3D's settings)
};

o3c::Tensor pose_tensor(const Eigen::Isometry3d& T) {  // camera -> world, as Model's T_frame_to_world
  std::vector<double> v(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v[size_t(4 * r + c)] = T.matrix()(r, c);
  return o3c::Tensor(v, {4, 4}, o3c::Float64);
}

Eigen::Isometry3d pose_from_tensor(const o3c::Tensor& t) {
  const o3c::Tensor T = t.To(o3c::Float64).Contiguous();
  const double* p = T.GetDataPtr<double>();
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out.matrix()(r, c) = p[4 * r + c];
  return out;
}

namespace odometry = open3d::t::pipelines::odometry;

// Stands in for Image::FilterBilateral(5, 5, 10) (IPP's bilateral filter: Gaussian weights of the
// value difference and the pixel distance over a 5×5 window) on a (H, W, 1) Float32 depth with NaN
// for invalid pixels. How IPP treats NaN is not known here; this keeps invalid pixels invalid and
// skips invalid neighbours.
o3g::Image filter_bilateral_cpu(const o3g::Image& depth, int kernel_size, float value_sigma, float dist_sigma) {
  const o3c::Tensor in = depth.AsTensor().Contiguous();
  const int64_t h = in.GetShape(0), w = in.GetShape(1);
  o3c::Tensor out(in.GetShape(), o3c::Float32, in.GetDevice());
  const float* src = in.GetDataPtr<float>();
  float* dst = out.GetDataPtr<float>();
  const int r = kernel_size / 2;
  const float kv = -0.5f / (value_sigma * value_sigma), ks = -0.5f / (dist_sigma * dist_sigma);
  for (int64_t y = 0; y < h; ++y)
    for (int64_t x = 0; x < w; ++x) {
      const float c = src[y * w + x];
      if (!std::isfinite(c)) {
        dst[y * w + x] = c;
        continue;
      }
      float sum = 0, wsum = 0;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int64_t yy = y + dy, xx = x + dx;
          if (yy < 0 || yy >= h || xx < 0 || xx >= w) continue;
          const float v = src[yy * w + xx];
          if (!std::isfinite(v)) continue;
          const float wt = std::exp(kv * (v - c) * (v - c) + ks * float(dx * dx + dy * dy));
          sum += wt * v;
          wsum += wt;
        }
      dst[y * w + x] = sum / wsum;
    }
  return o3g::Image(out);
}

// Model::TrackFrameToModel (odometry::RGBDOdometryMultiScale, Method::PointToPlane, identity
// initialisation) with Open3D 0.16's own public calls, filter_bilateral_cpu standing in for
// Image::FilterBilateral (see the header). Returns the input-frame-to-raycast-frame transformation.
odometry::OdometryResult track_frame_to_model(const slam::Frame& input_frame, const slam::Frame& raycast_frame,
                                              float depth_scale, float depth_max, float depth_diff,
                                              const std::vector<odometry::OdometryConvergenceCriteria>& criteria) {
  const odometry::OdometryLossParams params(depth_diff);
  const o3c::Device host("CPU:0");
  const o3c::Tensor trans = o3c::Tensor::Eye(4, o3c::Float64, host);
  o3g::Image source_depth = input_frame.GetDataAsImage("depth").ClipTransform(depth_scale, 0, depth_max, NAN);
  o3g::Image target_depth = raycast_frame.GetDataAsImage("depth").ClipTransform(depth_scale, 0, depth_max, NAN);
  o3c::Tensor intrinsics = raycast_frame.GetIntrinsics().To(host, o3c::Float64).Clone();

  const int64_t n_levels = int64_t(criteria.size());
  const size_t levels = criteria.size();
  std::vector<o3c::Tensor> source_vertex(levels), target_vertex(levels), target_normal(levels), intrinsic(levels);
  for (int64_t i = 0; i < n_levels; ++i) {  // pyramid, stored coarse first
    const size_t l = size_t(n_levels - 1 - i);
    source_vertex[l] = source_depth.CreateVertexMap(intrinsics, NAN).AsTensor();
    target_vertex[l] = target_depth.CreateVertexMap(intrinsics, NAN).AsTensor();
    target_normal[l] =
        filter_bilateral_cpu(target_depth, 5, 5, 10).CreateVertexMap(intrinsics, NAN).CreateNormalMap(NAN).AsTensor();
    intrinsic[l] = intrinsics.Clone();
    if (i != n_levels - 1) {
      source_depth = source_depth.PyrDownDepth(params.depth_outlier_trunc_ * 2, NAN);
      target_depth = target_depth.PyrDownDepth(params.depth_outlier_trunc_ * 2, NAN);
      intrinsics /= 2;
      intrinsics[-1][-1] = 1;
    }
  }
  odometry::OdometryResult result(trans, 0.0, 1.0);
  for (int64_t i = 0; i < n_levels; ++i)
    for (int iter = 0; iter < criteria[size_t(i)].max_iteration_; ++iter) {
      const auto delta = odometry::ComputeOdometryResultPointToPlane(
          source_vertex[size_t(i)], target_vertex[size_t(i)], target_normal[size_t(i)], intrinsic[size_t(i)],
          result.transformation_, params.depth_outlier_trunc_, params.depth_huber_delta_);
      result.transformation_ = delta.transformation_.Matmul(result.transformation_);
      if (std::abs(result.fitness_ - delta.fitness_) / result.fitness_ < criteria[size_t(i)].relative_fitness_ &&
          std::abs(result.inlier_rmse_ - delta.inlier_rmse_) / result.inlier_rmse_ < criteria[size_t(i)].relative_rmse_)
        break;
      result.inlier_rmse_ = delta.inlier_rmse_;
      result.fitness_ = delta.fitness_;
    }
  return result;
}

void print_ate(const char* who, const rrg::io::Trajectory& est, const rrg::io::Dataset& dataset) {
  if (!dataset.has_ground_truth()) {
    std::printf("%-8s ATE: the dataset has no ground truth\n", who);
    return;
  }
  const auto m = rrg::eval::evaluate_trajectory(est, dataset.ground_truth());
  std::printf("%-8s ATE RMSE %.3f cm (rigid SE(3) Umeyama, %zu poses; max %.3f cm, unaligned RMSE %.3f cm)\n", who,
              m.ate.rmse_cm, m.ate.matched, m.ate.max_cm, m.ate.rmse_unaligned_cm);
}

void run(const Options& o) {
  const rrg::Device cpu = rrg::Device::cpu();
  const auto dataset = rrg::io::open_dataset(o.dataset, o.flags.to_options());
  const rrg::Intrinsics K = dataset->intrinsics();
  const size_t n = o.frames > 0 ? std::min(dataset->size(), size_t(o.frames)) : dataset->size();

  // ---- ours: as `rrg track --device cpu` ----
  rrg::TrackingParams params;
  params.mode = rrg::parse_tracking_mode(o.mode);
  std::unique_ptr<rrg::MaskSource> masks;
  if (params.mode == rrg::TrackingMode::IcpOrbMask) {
    if (dataset->format() != rrg::io::DatasetFormat::Synth)
      throw std::runtime_error("--tracking icp+orb+mask needs the synthetic dataset's reflection masks; " +
                               o.dataset + " is " + rrg::io::to_string(dataset->format()));
    masks = std::make_unique<rrg::SynthReflectionMasks>(dataset->root());
  }
  rrg::TsdfParams tsdf;
  tsdf.voxel_size = o.voxel;
  tsdf.truncation = o.trunc > 0.0f ? o.trunc : 4.0f * o.voxel;  // rrg track's default
  tsdf.max_depth = o.max_depth;
  tsdf.band_sigmas = o.band_sigmas;  // ours as rrg track runs it; Open3D keeps its constant band
  tsdf.noise = params.icp.noise;
  rrg::TsdfVolume volume(tsdf, cpu);
  rrg::TsdfModelSource model(volume, K);
  rrg::Tracker tracker(params, K, cpu);

  // ---- Open3D: as examples/cpp/DenseSLAM.cpp on CPU:0 ----
  const o3c::Device o3d_cpu("CPU:0");
  const float trunc_mult = tsdf.truncation / tsdf.voxel_size;
  const o3c::Tensor intr = intrinsic_tensor(K);
  rrg::Intrinsics K_half = K;  // --o3d-round-pixels: floor(u + 0.5) = round(u) in Integrate's lookup
  K_half.cx += 0.5f;
  K_half.cy += 0.5f;
  const o3c::Tensor intr_integrate = intrinsic_tensor(K_half);
  // --o3d-half-voxel: the raycast reads voxel floor(p / s) at a point p of a ray, and voxel i holds the
  // TSDF at i·s, so its surface lies s/2 along +x, +y, +z on average; integrating in a world moved by
  // −s/2 (T_wc' = Translate(−s/2) T_wc) cancels that for the diagnostic.
  const o3c::Tensor shift_half_voxel =
      pose_tensor(Eigen::Isometry3d(Eigen::Translation3d(Eigen::Vector3d::Constant(-0.5 * double(o.voxel)))));
  std::unique_ptr<slam::Model> o3d_model;  // made at frame 0, from its pose
  slam::Frame input_frame(K.height, K.width, intr, o3d_cpu);
  slam::Frame raycast_frame(K.height, K.width, intr, o3d_cpu);
  o3c::Tensor T_frame_to_model;

  std::printf("%s: %zu frames %dx%d; voxel %.1f mm, truncation %.1f cm (Open3D trunc_voxel_multiplier %.2f), "
              "depth %.2f-%.2f m; ours %s; Open3D block resolution %d, depth_diff %.3f m, iterations %s%s\n",
              o.dataset.c_str(), n, K.width, K.height, tsdf.voxel_size * 1e3, tsdf.truncation * 1e2, trunc_mult,
              tsdf.min_depth, tsdf.max_depth, rrg::to_string(params.mode).c_str(), o.o3d_block_resolution,
              o.o3d_depth_diff, fmt::format("{}", fmt::join(o.o3d_iterations, ",")).c_str(),
              (std::string(o.o3d_round_pixels ? ", Integrate with cx, cy + 0.5 (--o3d-round-pixels)" : "") +
               (o.o3d_half_voxel ? ", Integrate in a world moved by -s/2 (--o3d-half-voxel)" : "")).c_str());
  std::fflush(stdout);

  rrg::io::Trajectory traj_ours, traj_o3d;
  Stage load, ours_input, ours_raycast, ours_track, ours_fuse, o3d_input, o3d_raycast, o3d_track, o3d_fuse;
  double ours_pre = 0, ours_icp = 0, ours_orb = 0;  // wall, from TrackResult
  size_t counts[3] = {0, 0, 0}, refined = 0, o3d_failed = 0, o3d_exceptions = 0;
  std::string o3d_first_error;
  Eigen::Isometry3f T_last = Eigen::Isometry3f::Identity();
  std::vector<odometry::OdometryConvergenceCriteria> criteria;
  for (int it : o.o3d_iterations) criteria.emplace_back(it);
  std::string log = "frame,ours_state,ours_icp_inlier_ratio,ours_icp_rmse_mm,ours_icp_iterations,open3d_ok,"
                    "open3d_fitness,open3d_inlier_rmse_mm,open3d_step_mm,open3d_range_map_warning\n";

  for (size_t i = 0; i < n; ++i) {
    Clock t0 = now();
    const rrg::io::Frame frame = dataset->load(i);
    Clock t1 = now();
    load.add(t0, t1);
    const Eigen::Isometry3d T_first =
        (i == 0 && frame.T_wc_gt) ? *frame.T_wc_gt : Eigen::Isometry3d::Identity();

    // ours
    rrg::TrackResult r;
    if (!o.open3d_only) {
      t0 = now();
      const auto depth = rrg::DeviceImage<float>::from_host(frame.depth, cpu);
      const auto color = rrg::DeviceImage<rrg::Color>::from_host(frame.color, cpu);
      t1 = now();
      ours_input.add(t0, t1);
      if (i == 0 && frame.T_wc_gt) tracker.set_initial_pose(T_first.cast<float>());
      if (i > 0) {  // the model at T_{k−1}, timed here (the tracker then reuses the cached raycast)
        t0 = now();
        model.model_at(T_last);
        t1 = now();
        ours_raycast.add(t0, t1);
      }
      t0 = now();
      r = tracker.track({i, &frame.color, &frame.depth, &depth}, model, masks.get());
      t1 = now();
      ours_track.add(t0, t1);
      ours_pre += r.ms_preprocess;
      ours_icp += r.ms_icp;
      ours_orb += r.ms_orb;
      if (r.state != rrg::TrackingState::Lost) {
        t0 = now();
        rrg::integrate(volume, depth, color, K, r.T_wc, nullptr, tracker.normal_depth());
        model.invalidate();
        t1 = now();
        ours_fuse.add(t0, t1);
      } else {
        spdlog::warn("ours: frame {} lost ({})", i, r.note);
      }
      T_last = r.T_wc;
      traj_ours.push_back({frame.timestamp, r.T_wc.cast<double>()});
      ++counts[int(r.state)];
      refined += r.orb_refined;
    }

    // Open3D
    if (i == 0) {  // not timed, as our TsdfVolume's construction (it preallocates the block pool)
      T_frame_to_model = pose_tensor(T_first);
      o3d_model = std::make_unique<slam::Model>(o.voxel, o.o3d_block_resolution, o.o3d_block_count,
                                                T_frame_to_model, o3d_cpu);
    }
    t0 = now();
    const o3c::Tensor d(frame.depth.data(), {K.height, K.width, 1}, o3c::Float32, o3d_cpu);
    const o3c::Tensor c(frame.color.data()->data(), {K.height, K.width, 3}, o3c::Float32, o3d_cpu);
    input_frame.SetDataFromImage("depth", o3g::Image(d));
    input_frame.SetDataFromImage("color", o3g::Image(c));
    t1 = now();
    o3d_input.add(t0, t1);
    bool tracking_success = true;
    double o3d_fitness = 0, o3d_rmse = 0, o3d_step = 0;
    const size_t warnings_before = g_range_map_warnings;
    if (i > 0) {
      try {
        t0 = now();
        // At T_{k−1} (UpdateFramePose(k−1) was the last call); the example does this at the end of
        // frame k−1, which is the same call on the same state.
        o3d_model->SynthesizeModelFrame(raycast_frame, 1.0f, tsdf.min_depth, tsdf.max_depth, trunc_mult, false);
        t1 = now();
        o3d_raycast.add(t0, t1);
        const auto result =
            track_frame_to_model(input_frame, raycast_frame, 1.0f, tsdf.max_depth, o.o3d_depth_diff, criteria);
        const Clock t2 = now();
        o3d_track.add(t1, t2);
        const Eigen::Isometry3d dT = pose_from_tensor(result.transformation_);
        const double translation = dT.translation().norm();
        o3d_fitness = result.fitness_;
        o3d_rmse = result.inlier_rmse_;
        o3d_step = translation;
        if (result.fitness_ >= o.o3d_min_fitness && translation < o.o3d_max_translation) {
          T_frame_to_model = T_frame_to_model.Matmul(result.transformation_);
        } else {
          tracking_success = false;
          ++o3d_failed;
          spdlog::warn("Open3D: frame {}: tracking failed (fitness {:.3f}, translation {:.3f} m); previous pose kept", i,
                       result.fitness_, translation);
        }
      } catch (const std::exception& e) {
        tracking_success = false;
        ++o3d_failed;
        ++o3d_exceptions;
        if (o3d_first_error.empty()) o3d_first_error = e.what();
        spdlog::warn("Open3D: frame {}: exception, previous pose kept: {}", i, e.what());
      }
    }
    o3d_model->UpdateFramePose(int(i), T_frame_to_model);
    if (tracking_success) {
      t0 = now();
      if (o.o3d_round_pixels) input_frame.SetIntrinsics(intr_integrate);
      if (o.o3d_half_voxel) o3d_model->T_frame_to_world_ = shift_half_voxel.Matmul(T_frame_to_model);
      o3d_model->Integrate(input_frame, 1.0f, tsdf.max_depth, trunc_mult);
      if (o.o3d_round_pixels) input_frame.SetIntrinsics(intr);
      if (o.o3d_half_voxel) o3d_model->T_frame_to_world_ = T_frame_to_model;
      t1 = now();
      o3d_fuse.add(t0, t1);
    }
    traj_o3d.push_back({frame.timestamp, pose_from_tensor(T_frame_to_model)});
    log += fmt::format("{},{},{:.4f},{:.3f},{},{},{:.4f},{:.3f},{:.2f},{}\n", i, rrg::to_string(r.state),
                       r.icp.inlier_ratio, r.icp.rmse_m * 1e3, r.icp.iterations, int(tracking_success), o3d_fitness,
                       o3d_rmse * 1e3, o3d_step * 1e3, int(g_range_map_warnings > warnings_before));

    if ((i + 1) % size_t(std::max(1, o.progress)) == 0 || i + 1 == n) {
      const double k = double(i + 1);
      spdlog::info("{}/{} frames; ours {} ok / {} degraded / {} lost, {:.0f} ms/frame; Open3D {} failed, {:.0f} ms/frame",
                   i + 1, n, counts[0], counts[1], counts[2],
                   (ours_input.wall + ours_raycast.wall + ours_track.wall + ours_fuse.wall) / k, o3d_failed,
                   (o3d_input.wall + o3d_raycast.wall + o3d_track.wall + o3d_fuse.wall) / k);
    }
  }

  if (!o.out_dir.empty()) {
    std::filesystem::create_directories(o.out_dir);
    const std::string mode_tag = [&] {
      std::string s = o.mode;
      std::replace(s.begin(), s.end(), '+', '_');
      return s;
    }();
    if (!o.open3d_only)
      rrg::io::write_tum_trajectory(std::filesystem::path(o.out_dir) / ("ours_" + mode_tag + ".txt"), traj_ours);
    rrg::io::write_tum_trajectory(std::filesystem::path(o.out_dir) / "open3d.txt", traj_o3d);
  }

  if (!o.log.empty()) {
    std::ofstream f(o.log);
    f << log;
    if (!f) throw std::runtime_error("cannot write " + o.log);
  }
  const double per = 1.0 / double(n);
  if (!o.open3d_only)
    std::printf("\nours:   %zu frames: %zu ok, %zu degraded, %zu lost; %zu orb-refined, %zu keyframes\n", n, counts[0],
              counts[1], counts[2], refined, tracker.keyframes().size());
  std::printf("Open3D: %zu frames: %zu tracking failures (%zu exceptions%s%s); %zu raycasts warned \"Could not "
              "generate full range map\"\n", n, o3d_failed, o3d_exceptions,
              o3d_first_error.empty() ? "" : "; first: ", o3d_first_error.c_str(), g_range_map_warnings);
  if (!o.open3d_only) print_ate("ours", traj_ours, *dataset);
  print_ate("Open3D", traj_o3d, *dataset);
  std::printf("\nms/frame (each stage's total / %zu frames)       wall     CPU\n", n);
  auto row = [&](const char* what, const Stage& s) { std::printf("  %-40s %8.2f %8.2f\n", what, s.wall * per, s.cpu * per); };
  auto total = [](std::initializer_list<Stage> stages) {
    Stage t;
    for (const Stage& s : stages) t.wall += s.wall, t.cpu += s.cpu;
    return t;
  };
  row("dataset load (both; not counted below)", load);
  row("ours: upload", ours_input);
  row("ours: raycast (TSDF at T_k-1)", ours_raycast);
  row("ours: track (preprocess + ICP + ORB)", ours_track);
  std::printf("  %-40s %8.2f / %.2f / %.2f (wall)\n", "  of which preprocess / ICP / ORB+BA", ours_pre * per,
              ours_icp * per, ours_orb * per);
  row("ours: fusion", ours_fuse);
  row("ours: total", total({ours_input, ours_raycast, ours_track, ours_fuse}));
  row("Open3D: input (tensors, SetDataFromImage)", o3d_input);
  row("Open3D: raycast (SynthesizeModelFrame)", o3d_raycast);
  row("Open3D: track (TrackFrameToModel body)", o3d_track);
  row("Open3D: integrate (Integrate)", o3d_fuse);
  row("Open3D: total", total({o3d_input, o3d_raycast, o3d_track, o3d_fuse}));
  if (!o.out_dir.empty()) std::printf("trajectories (TUM) -> %s\n", o.out_dir.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Dense SLAM: rrg track (tracking + TSDF fusion) vs Open3D 0.16 t::pipelines::slam::Model (CPU)"};
  Options o;
  app.add_option("dataset,--dataset", o.dataset, "dataset folder (TUM, 7-Scenes, Replica, synth)")->required();
  app.add_option("--frames", o.frames, "first N frames (0 = all)")->capture_default_str()->check(CLI::NonNegativeNumber);
  app.add_option("--voxel", o.voxel, "voxel size, metres (both)")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--band-sigmas", o.band_sigmas, "ours: k of the truncation band max(ε, k σ_n(d)), as rrg track");
  app.add_option("--trunc", o.trunc, "truncation, metres (both; default 4 x voxel, as rrg track)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-depth", o.max_depth, "depth range limit, metres (both)")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--tracking", o.mode, "ours: icp | icp+orb | icp+orb+mask")
      ->capture_default_str()
      ->check(CLI::IsMember({"icp", "icp+orb", "icp+orb+mask"}));
  app.add_option("--out-dir", o.out_dir, "write ours_<mode>.txt and open3d.txt (TUM) here");
  app.add_option("--progress", o.progress, "progress line every N frames")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--o3d-block-resolution", o.o3d_block_resolution, "Open3D voxels per block edge (example: 16)")
      ->capture_default_str();
  app.add_option("--o3d-block-count", o.o3d_block_count, "Open3D initial block capacity (example: 10000)")
      ->capture_default_str();
  app.add_option("--o3d-iterations", o.o3d_iterations,
                 "Open3D odometry iterations per level, coarse to fine (TrackFrameToModel default: 6 3 1)")
      ->capture_default_str()
      ->delimiter(',');
  app.add_flag("--o3d-round-pixels", o.o3d_round_pixels,
               "diagnostic, not Open3D's loop: VoxelBlockGrid::Integrate looks a voxel's depth up at pixel "
               "(int)u, a half-pixel shift against the pixel-centre convention of its raycast and odometry; give "
               "Integrate cx + 0.5, cy + 0.5 so the lookup rounds");
  app.add_flag("--o3d-half-voxel", o.o3d_half_voxel,
               "diagnostic, not Open3D's loop: its raycast reads voxel floor(p / s) without interpolation, so the "
               "model surface sits s/2 along +x+y+z on average; integrate in a world moved by -s/2 to cancel it");
  app.add_flag("--open3d-only", o.open3d_only, "run only Open3D (for the diagnostics above)");
  app.add_option("--log", o.log, "per-frame CSV: our ICP quality, Open3D fitness / inlier RMSE / step");
  app.add_option("--o3d-depth-diff", o.o3d_depth_diff, "Open3D odometry correspondence limit, metres (example: 0.07)")
      ->capture_default_str();
  app.add_option("--o3d-min-fitness", o.o3d_min_fitness, "Open3D failure test: fitness below (example: 0.1)")
      ->capture_default_str();
  app.add_option("--o3d-max-translation", o.o3d_max_translation,
                 "Open3D failure test: frame-to-model translation at or above, metres (example: 0.15)")
      ->capture_default_str();
  rrg::io::add_dataset_flags(app, o.flags);
  CLI11_PARSE(app, argc, argv);
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Warning);
  // VoxelBlockGrid::RayCast warns once per call when its range map runs out of fragments; count it
  // instead of printing it every frame.
  open3d::utility::Logger::GetInstance().SetPrintFunction([](const std::string& msg) {
    if (msg.find("full range map") != std::string::npos && g_range_map_warnings++ > 0) return;
    std::fputs(msg.c_str(), stderr);
    std::fputs("\n", stderr);
  });
  try {
    run(o);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
