#include "core/synth/sequence.h"

#include "core/io/image_io.h"
#include "core/io/ply.h"
#include "core/synth/exposure.h"
#include "core/synth/hash.h"
#include "core/synth/mesh_export.h"
#include "core/synth/sequence_files.h"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <functional>
#include <stdexcept>

namespace rrg::synth {

namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

constexpr int kMaxSize = 8192;
constexpr float kFreeMargin = 0.12f;  // metres kept between a camera centre and any solid

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
// Process CPU time of all threads: on a shared machine it says what the work costs, whatever the load.
double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// Runs independent tasks (file writes) on the OpenMP threads; rethrows the first failure.
void run_parallel(const std::vector<std::function<void()>>& tasks, int threads) {
  std::vector<std::exception_ptr> errors(tasks.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int i = 0; i < int(tasks.size()); ++i) {
    try {
      tasks[size_t(i)]();
    } catch (...) {
      errors[size_t(i)] = std::current_exception();
    }
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

void check_output_folder(const SynthParams& p) {
  std::error_code ec;
  if (!fs::exists(p.out, ec)) return;
  if (!fs::is_directory(p.out, ec)) throw std::runtime_error("output path " + p.out.string() + " exists and is not a folder");
  if (!fs::is_empty(p.out, ec) && !p.overwrite)
    throw std::runtime_error("output folder " + p.out.string() + " is not empty (pass --overwrite to write into it)");
}

// Renders one view (plus the depth model) and returns the file writes for it.
struct ViewWriter {
  const Scene& scene;
  const SynthParams& params;
  const Intrinsics& K;
  DepthNoiseParams noise;
  double render_seconds = 0.0, render_cpu_seconds = 0.0;

  // exposure: the colour's gain (1 = as rendered).
  std::vector<std::function<void()>> render(const Eigen::Isometry3d& T_wc, const fs::path& root, size_t index,
                                            uint32_t noise_frame, float exposure = 1.0f) {
    const auto t0 = Clock::now();
    const double c0 = cpu_seconds();
    RenderParams rp = params.render;
    rp.threads = params.threads;
    rp.virtual_mirror_depth = params.mirror_depth == MirrorDepth::Virtual;
    rp.mirror_f0 = noise.mirror_f0;
    auto out = std::make_shared<RenderOutput>(render_view(scene, K, T_wc.cast<float>(), rp));
    if (noise.gaussian || noise.edge_dropout || noise.invalid_on_mirrors)
      apply_depth_noise(out->depth, out->material, scene, noise, noise_frame, params.seed);
    if (exposure != 1.0f) apply_exposure(out->color, exposure);
    render_seconds += seconds_since(t0);
    render_cpu_seconds += cpu_seconds() - c0;
    const std::string name = frame_file_name(index);
    return {[out, root, name] { io::write_color_png(root / "rgb" / name, out->color, 1); },
            [out, root, name] { io::write_depth_png(root / "depth" / name, out->depth, kDepthScale, 1); },
            [out, root, name] { io::write_labels_png(root / "labels" / name, out->labels, 1); },
            [out, root, name] { io::write_mask_png(root / "reflection" / name, out->reflective, 1); },
            [out, root, name] { io::write_labels_png(root / "planes" / name, out->planes, 1); }};
  }
};

}  // namespace

MirrorDepth parse_mirror_depth(const std::string& text) {
  if (text == "surface") return MirrorDepth::Surface;
  if (text == "invalid") return MirrorDepth::Invalid;
  if (text == "virtual") return MirrorDepth::Virtual;
  throw std::invalid_argument("--mirror-depth must be 'surface', 'invalid' or 'virtual', got '" + text + "'");
}

const char* to_string(MirrorDepth m) {
  switch (m) {
    case MirrorDepth::Invalid: return "invalid";
    case MirrorDepth::Virtual: return "virtual";
    default: return "surface";
  }
}

void validate(const SynthParams& p) {
  if (p.frames <= 0) throw std::invalid_argument("--frames must be > 0, got " + std::to_string(p.frames));
  if (p.width <= 0 || p.width > kMaxSize || p.height <= 0 || p.height > kMaxSize)
    throw std::invalid_argument("image size must be 1..8192 x 1..8192, got " + std::to_string(p.width) + "x" +
                                std::to_string(p.height));
  if (!(p.fps > 0.0) || !std::isfinite(p.fps)) throw std::invalid_argument("--fps must be > 0");
  if (!(p.speed > 0.0) || !std::isfinite(p.speed) || p.speed > 10.0)
    throw std::invalid_argument("--speed must be in (0, 10] m/s");
  if (p.novel < 0) throw std::invalid_argument("--novel must be >= 0, got " + std::to_string(p.novel));
  if (p.threads < 0) throw std::invalid_argument("--threads must be >= 0, got " + std::to_string(p.threads));
  if (p.out.empty()) throw std::invalid_argument("--out is required");
  if (p.render.rough_samples < 1 || p.render.rough_samples > 64)
    throw std::invalid_argument("rough_samples must be 1..64");
  if (!(p.mesh_max_edge > 0.0f)) throw std::invalid_argument("mesh edge must be > 0");
  bool known = false;
  for (const PresetInfo& info : preset_list()) known = known || info.name == p.preset;
  if (!known) throw std::invalid_argument("unknown preset '" + p.preset + "' (valid presets: " + preset_names() + ")");
}

Intrinsics default_intrinsics(int width, int height) {
  const float f = 0.8f * float(width);
  return {f, f, 0.5f * float(width - 1), 0.5f * float(height - 1), width, height};
}

CameraPath make_camera_path(const SceneSpec& spec) { return CameraPath(spec.waypoints); }

SequencePlan plan_sequence(const SceneSpec& spec, const CameraPath& path, const SynthParams& params) {
  SequencePlan plan;
  plan.K = default_intrinsics(params.width, params.height);
  plan.start_offset = params.seed == 0 ? 0.0 : path.length() * double(unit_float(hash_combine(params.seed, 0x57a7u)));
  for (int i = 0; i < params.frames; ++i) {
    const double t = double(i) / params.fps;
    plan.frames.push_back({t, path.pose_at(plan.start_offset + params.speed * t)});
  }
  // Novel views: uniformly spread over the recorded stretch of the loop, then pushed off it by
  // 3-6 cm and rotated by 2-5 degrees (halved until the centre stays in free space).
  const double duration = double(params.frames) / params.fps;
  for (int k = 0; k < params.novel; ++k) {
    const double t = (double(k) + 0.5) / double(params.novel) * duration;
    const Eigen::Isometry3d base = path.pose_at(plan.start_offset + params.speed * t);
    const uint32_t key = hash3(params.seed, uint32_t(k), 0x90e1u);
    Vector3d dir(signed_float(hash_combine(key, 1)), signed_float(hash_combine(key, 2)), signed_float(hash_combine(key, 3)));
    Vector3d axis(signed_float(hash_combine(key, 4)), signed_float(hash_combine(key, 5)), signed_float(hash_combine(key, 6)));
    dir = dir.norm() > 1e-3 ? dir.normalized() : Vector3d::UnitX();
    axis = axis.norm() > 1e-3 ? axis.normalized() : Vector3d::UnitZ();
    double dist = 0.03 + 0.03 * unit_float(hash_combine(key, 7));
    double angle = (2.0 + 3.0 * unit_float(hash_combine(key, 8))) * 3.14159265358979 / 180.0;
    Eigen::Isometry3d T = base;
    for (int attempt = 0; attempt < 6; ++attempt, dist *= 0.5, angle *= 0.5) {
      T = base;
      T.translation() += dist * dir;
      T.linear() = base.linear() * Eigen::AngleAxisd(angle, axis).toRotationMatrix();
      if (spec.scene.is_free(T.translation().cast<float>(), kFreeMargin)) break;
      T = base;
    }
    plan.novel.push_back({t, T});
  }
  return plan;
}

SynthStats generate_sequence(const SynthParams& params) {
  validate(params);
  check_output_folder(params);
  const auto t_start = Clock::now();
  const double cpu_start = cpu_seconds();
  const int threads = params.threads > 0 ? params.threads : omp_get_max_threads();
  const SceneSpec spec = make_preset(params.preset, params.seed);
  const CameraPath path = make_camera_path(spec);
  const SequencePlan plan = plan_sequence(spec, path, params);
  spdlog::info("synth: preset {} ({} primitives, {} planes), {} frames + {} novel views at {}, {} threads -> {}",
               params.preset, spec.scene.primitives.size(), spec.scene.planes().size(), params.frames, params.novel,
               plan.K.to_string(), threads, params.out.string());

  ViewWriter writer{spec.scene, params, plan.K, {}};
  writer.noise.gaussian = params.noise;
  writer.noise.edge_dropout = params.noise;
  writer.noise.invalid_on_mirrors = params.mirror_depth == MirrorDepth::Invalid;

  const std::string title = "rrg synth " + params.preset;
  auto write_metadata = [&](const fs::path& root, const io::Trajectory& poses) {
    write_frame_list(root / "rgb.txt", poses, "rgb", title);
    write_frame_list(root / "depth.txt", poses, "depth", title);
    io::write_tum_trajectory(root / "groundtruth.txt", poses);
    write_camera_json(root / "camera.json", plan.K);
  };

  fs::create_directories(params.out);
  for (size_t i = 0; i < plan.frames.size(); ++i) {
    const float gain = params.exposure ? exposure_gain(plan.frames[i].timestamp, params.seed) : 1.0f;
    run_parallel(writer.render(plan.frames[i].T_wc, params.out, i, uint32_t(i), gain), threads);
    if ((i + 1) % 50 == 0 || i + 1 == plan.frames.size())
      spdlog::info("synth: frame {}/{} ({:.1f} frames/s rendering)", i + 1, plan.frames.size(),
                   double(i + 1) / std::max(writer.render_seconds, 1e-9));
  }
  write_metadata(params.out, plan.frames);
  if (!plan.novel.empty()) {
    const fs::path novel_root = params.out / "novel";
    for (size_t k = 0; k < plan.novel.size(); ++k)
      run_parallel(writer.render(plan.novel[k].T_wc, novel_root, k, 0x80000000u + uint32_t(k)), threads);
    write_metadata(novel_root, plan.novel);
    write_categories_json(novel_root / "categories.json", spec.scene);
    write_planes_json(novel_root / "planes.json", spec.scene);
    spdlog::info("synth: {} novel views written to {}", plan.novel.size(), novel_root.string());
  }
  write_categories_json(params.out / "categories.json", spec.scene);
  write_planes_json(params.out / "planes.json", spec.scene);
  if (params.write_mesh) {
    const TriangleMesh mesh = scene_mesh(spec.scene, {params.mesh_max_edge});
    io::write_ply_mesh(params.out / "mesh_gt.ply", mesh);
    spdlog::info("synth: mesh_gt.ply with {} vertices, {} triangles", mesh.vertices.size(), mesh.triangles.size());
  }
  write_scene_json(params.out / "scene.json", spec, path, params, plan);

  SynthStats stats;
  stats.frames = params.frames;
  stats.novel = params.novel;
  stats.render_seconds = writer.render_seconds;
  stats.total_seconds = seconds_since(t_start);
  stats.render_cpu_seconds = writer.render_cpu_seconds;
  stats.total_cpu_seconds = cpu_seconds() - cpu_start;
  return stats;
}

}  // namespace rrg::synth
