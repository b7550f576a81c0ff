#include "core/slam/runner.h"

#include "core/common/ordered_prefetch.h"
#include "core/eval/image_metrics.h"
#include "core/eval/mesh_metrics.h"
#include "core/eval/observed_mesh_metrics.h"
#include "core/eval/trajectory_metrics.h"
#include "core/io/atomic_file.h"
#include "core/io/draco_mesh.h"
#include "core/io/image_io.h"
#include "core/io/ply.h"
#include "core/io/synth_layout.h"
#include "core/io/trajectory.h"
#include "core/planes/plane_metrics.h"
#include "core/planes/semantic_labels.h"
#include "core/slam/run_outputs.h"

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

namespace rrg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Pooled squared error over masked pixels, for PSNR over the reflective pixels of many views.
struct MaskedSse {
  double sse = 0;
  size_t pixels = 0;
  void add(const Color& est, const Color& ref) {
    sse += double((est - ref).squaredNorm());
    ++pixels;
  }
  void add(const ColorImage& est, const ColorImage& ref, const MaskImage& mask) {
    for (size_t k = 0; k < ref.size(); ++k)
      if (mask[k]) add(est[k], ref[k]);
  }
  double psnr() const { return pixels ? 10.0 * std::log10(1.0 / (sse / double(3 * pixels))) : 0.0; }
};

// Ground truth of a synthetic view for the reflective scores: the reflection mask and the plane ids.
struct ReflectiveTruth {
  MaskImage reflection;
  LabelImage planes;
};

// The plane ids only where the dataset has them (per-plane scores are skipped without).
ReflectiveTruth read_reflective_truth(const std::filesystem::path& root, size_t i) {
  const bool planes = std::filesystem::exists(io::synth_extra_path(root, "planes", i));
  return {io::read_synth_reflection(root, i), planes ? io::read_synth_planes(root, i) : LabelImage()};
}

struct ScoreAccumulator {
  double psnr = 0, ssim = 0;
  size_t views = 0;
  MaskedSse reflective;
  std::map<int, GtPlane> reflective_planes;  // ground-truth reflective planes (synth), by id
  std::map<int, MaskedSse> by_plane;
  void add(const ColorImage& est, const ColorImage& ref, const ReflectiveTruth* truth) {
    psnr += std::min(eval::psnr(est, ref), 100.0);
    ssim += eval::ssim(est, ref);
    ++views;
    if (!truth) return;
    reflective.add(est, ref, truth->reflection);
    if (truth->planes.width() != ref.width() || truth->planes.height() != ref.height()) return;
    for (size_t k = 0; k < ref.size(); ++k)  // one pass: each pixel to its reflective plane, if any
      if (const int id = int(truth->planes[k]); id != 0 && reflective_planes.count(id)) by_plane[id].add(est[k], ref[k]);
  }
  ImageScores scores() const {
    ImageScores s;
    s.views = views;
    if (views) s.psnr = psnr / double(views), s.ssim = ssim / double(views);
    s.psnr_reflective = reflective.psnr();
    s.reflective_pixels = reflective.pixels;
    for (const auto& [id, sse] : by_plane) s.reflective_planes.push_back({id, reflective_planes.at(id).name, sse.pixels, sse.psnr()});
    return s;
  }
};

// The reflective planes of a synthetic dataset's planes.json (none without the file).
std::map<int, GtPlane> reflective_gt_planes(const std::filesystem::path& file) {
  std::map<int, GtPlane> out;
  if (!std::filesystem::exists(file)) return out;
  for (auto& [id, p] : read_gt_planes(file))
    if (p.reflective) out.emplace(id, std::move(p));
  return out;
}

// A one-line progress bar with live FPS on stderr (rewritten in place on a terminal).
class ProgressBar {
 public:
  ProgressBar(size_t total, bool enabled) : total_(total), enabled_(enabled), t0_(Clock::now()) {}
  void update(size_t done, const std::string& extra) {
    if (!enabled_) return;
    const double s = ms_since(t0_) / 1000.0;
    const bool last = done == total_;
    if (!last && s - last_s_ < 0.5) return;
    last_s_ = s;
    const int width = 30, filled = int(double(width) * double(done) / double(std::max<size_t>(1, total_)));
    std::fprintf(stderr, "\r[%s%s] %zu/%zu  %.1f FPS  %s", std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(width - filled), '.').c_str(), done, total_, s > 0 ? double(done) / s : 0.0,
                 extra.c_str());
    if (last) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  size_t total_;
  bool enabled_;
  Clock::time_point t0_;
  double last_s_ = -1;
};

std::string choose_semantics(const RunOptions& o, const io::Dataset& dataset, SessionConfig& config) {
  std::string s = o.semantics;
  const bool has_labels = dataset.format() == io::DatasetFormat::Synth &&
                          std::filesystem::exists(io::synth_scene_file(dataset.root(), "categories.json"));
  if (s == "auto") s = has_labels ? "labels" : "none";
  if (s == "labels") {
    if (!has_labels)
      throw std::invalid_argument("run: --semantics labels needs label images and categories.json (a synthetic dataset); " +
                                  dataset.root().string() + " has none (use none or remote)");
    if (config.categories.empty())
      for (const auto& [id, name] : read_category_table(io::synth_scene_file(dataset.root(), "categories.json")).names)
        config.categories[id] = name;
  }
  return s;
}

}  // namespace

std::vector<NamedPose> read_render_poses(const std::filesystem::path& file) {
  std::ifstream f(file);
  if (!f) throw std::runtime_error("render poses: cannot open " + file.string());
  std::vector<NamedPose> poses;
  std::string line;
  for (size_t line_no = 1; std::getline(f, line); ++line_no) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream in(line);
    std::string name;
    if (!(in >> name)) continue;
    double v[7];
    for (double& x : v)
      if (!(in >> x) || !std::isfinite(x))
        throw std::runtime_error("render poses: " + file.string() + ":" + std::to_string(line_no) +
                                 ": expected 'name tx ty tz qx qy qz qw'");
    Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > 0.1)
      throw std::runtime_error("render poses: " + file.string() + ":" + std::to_string(line_no) + ": quaternion is not unit");
    q.normalize();
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    char* end = nullptr;
    std::strtod(name.c_str(), &end);
    if (end && *end == '\0') {  // a TUM line: the first column is a timestamp
      char buf[16];
      std::snprintf(buf, sizeof(buf), "%06zu", poses.size());
      name = buf;
    }
    for (char& c : name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) c = '_';
    poses.push_back({name, T.cast<float>()});
  }
  return poses;
}

SessionFrame to_session_frame(io::Frame&& f) {
  SessionFrame frame;
  frame.index = int64_t(f.index);
  frame.timestamp = f.timestamp;
  frame.color = std::move(f.color);
  frame.depth = std::move(f.depth);
  return frame;
}

RunResult run_dataset(const RunOptions& o) {
  const auto dataset = io::open_dataset(o.dataset, o.dataset_options);
  SessionConfig config = o.config;
  config.K = dataset->intrinsics();
  config.semantics = choose_semantics(o, *dataset, config);
  if (config.gt_poses && !dataset->has_ground_truth())
    throw std::invalid_argument("run: --gt-poses needs a dataset with ground-truth poses");
  size_t n = o.max_frames > 0 ? std::min(dataset->size(), o.max_frames) : dataset->size();
  if (n == 0) throw std::invalid_argument("run: " + o.dataset.string() + " has no frames");
  for (size_t i : o.decomposition_frames)  // before the run, not after an hour of it
    if (i >= n) throw std::invalid_argument("run: --decomposition frame " + std::to_string(i) + " is beyond the run (" +
                                            std::to_string(n) + " frames)");
  if (!(o.rate_hz >= 0) || !std::isfinite(o.rate_hz))
    throw std::invalid_argument("run: --rate must be a frame rate >= 0 (0 = as fast as frames load)");
  config.validate();  // a refused config leaves no output folder behind
  if (!o.out.empty()) std::filesystem::create_directories(o.out);
  if (!o.out.empty())
    io::write_atomically(o.out / "config.yaml", [&](const std::filesystem::path& tmp) { std::ofstream(tmp) << config_to_yaml(config); });

  Session session(config);
  spdlog::info("run: {} ({} frames, {}x{}) on {}, tracking {}, semantics {}, reflections {}, {}", o.dataset.string(), n,
               config.K.width, config.K.height, config.device.to_string(),
               config.gt_poses ? "off (ground-truth poses)" : to_string(config.tracking.mode), config.semantics,
               config.mapping.reflections ? "on" : "off", to_string(config.schedule()) + " mapping");

  RunResult result;
  ProgressBar bar(n, o.progress);
  ScoreAccumulator train;
  std::vector<std::pair<size_t, ColorImage>> train_views;  // scored at the end (the final map)
  const auto wall0 = Clock::now();
  // Frames are decoded ahead, on loader threads, while the session processes the current one (the
  // PNG decoding of a 1280x720 frame takes as long as a CUDA session's whole pre-mapping). A frame
  // that cannot be read still stops the run at that frame, after the ones before it.
  const size_t loaders = std::clamp<size_t>(std::thread::hardware_concurrency() / 4, 1, 4);
  OrderedPrefetch<SessionFrame> loaded(
      [&](size_t i) {
        io::Frame f = dataset->load(i);
        const std::optional<Eigen::Isometry3d> T_gt = f.T_wc_gt;
        SessionFrame frame = to_session_frame(std::move(f));
        if (config.semantics == "labels") frame.labels = io::read_synth_labels(dataset->root(), i);
        if (T_gt && (i == 0 || config.gt_poses)) frame.pose = T_gt->cast<float>();
        return frame;
      },
      n, loaders + 2, loaders);
  for (size_t i = 0; i < n; ++i) {
    SessionFrame frame = loaded.next();
    // A sensor's stream: frame i arrives i / rate after the first; its latency is from then until
    // process() returns (a session that keeps up holds it near one frame's pre-mapping).
    const auto due = wall0 + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(o.rate_hz > 0 ? double(i) / o.rate_hz : 0.0));
    while (o.rate_hz > 0 && Clock::now() < due && !(o.stop && o.stop()))  // Ctrl-C stays prompt at slow rates
      std::this_thread::sleep_for(std::min<Clock::duration>(due - Clock::now(), std::chrono::milliseconds(100)));
    const FrameReport r = session.process(frame);
    if (o.rate_hz > 0) {
      const double latency = std::max(0.0, ms_since(due));  // (a frame a stop let in early: 0)
      result.timings.latency_mean_ms += latency;
      result.timings.latency_max_ms = std::max(result.timings.latency_max_ms, latency);
    }
    if (r.state == TrackingState::Lost) spdlog::debug("run: frame {} lost: {}", i, r.note);
    if (o.train_stride > 0 && i % o.train_stride == 0) train_views.emplace_back(i, std::move(frame.color));
    const SessionStatus st = session.status();
    bar.update(i + 1, fmt::format("{} G_b {} G_r {} planes", st.mapping.base_gaussians, st.mapping.reflection_gaussians,
                                  st.reflective_planes.size()));
    if (i + 1 < n && o.stop && o.stop()) {
      spdlog::warn("run: stopped after frame {} of {}; finishing with the frames processed", i + 1, n);
      n = i + 1;
      result.metrics.interrupted = true;
    }
  }
  session.finish();
  const double wall_ms = ms_since(wall0);

  // --- timings ---
  const auto reports = session.reports();
  const SessionStatus st = session.status();
  RunTimings& t = result.timings;
  t.schedule = to_string(config.schedule());
  t.rate_hz = o.rate_hz;
  t.latency_mean_ms /= double(std::max<size_t>(n, 1));
  for (const FrameReport& r : reports) {
    t.mean.raycast += r.times.raycast, t.mean.preprocess += r.times.preprocess, t.mean.icp += r.times.icp;
    t.mean.orb += r.times.orb, t.mean.mask += r.times.mask, t.mean.fuse += r.times.fuse, t.mean.stream += r.times.stream;
    t.mean.identify += r.times.identify;
    t.mean.mapping += r.times.mapping, t.mean.total += r.times.total;
  }
  const double per = 1.0 / double(reports.size());
  for (double* v : {&t.mean.raycast, &t.mean.preprocess, &t.mean.icp, &t.mean.orb, &t.mean.mask, &t.mean.fuse, &t.mean.stream,
                    &t.mean.identify, &t.mean.mapping, &t.mean.total})
    *v *= per;
  t.premapping_ms = t.mean.raycast + t.mean.preprocess + t.mean.icp + t.mean.orb + t.mean.fuse + t.mean.identify;
  t.mapping_steps = st.mapping.steps;
  t.mapping_iterations = st.mapping.iterations;
  t.mapping_waits = st.mapping.waits;
  const double per_step = st.mapping.steps ? 1.0 / double(st.mapping.steps) : 0.0;
  t.mapping_step_ms = st.mapping.ms_total * per_step;
  t.mapping_raycast_ms = st.mapping.ms_raycast * per_step;
  t.mapping_densify_ms = st.mapping.ms_densify * per_step;
  t.mapping_optimise_ms = st.mapping.ms_optimise * per_step;
  t.mapping_optimise = st.mapping.optimise.scaled(per_step);
  t.mapping_prune_ms = st.mapping.ms_prune * per_step;
  t.load_ms = loaded.produce_ms() / double(n);  // approximate after an interrupt (frames loaded ahead)
  t.load_wait_ms = loaded.wait_ms() / double(n);
  t.wall_ms_per_frame = wall_ms / double(n);

  // --- metrics ---
  RunMetrics& m = result.metrics;
  m.frames = n;
  m.lost = size_t(st.lost);
  m.wall_s = wall_ms / 1000.0;
  m.fps = double(n) / m.wall_s;
  m.base_gaussians = st.mapping.base_gaussians;
  m.reflection_gaussians = st.mapping.reflection_gaussians;
  m.reflective_planes = int64_t(st.reflective_planes.size());
  m.tsdf_blocks = st.tsdf_blocks;
  m.tsdf_resident_blocks = st.resident_blocks;
  m.tsdf_device_bytes = st.tsdf_device_bytes;
  m.tsdf_host_bytes = st.host_bytes;
  for (const FrameReport& r : reports) {
    m.filled_frames += r.filled_pixels > 0;
    m.filled_pixels += r.filled_pixels;
  }
  if (m.filled_frames > 0)
    spdlog::info("run: depth the sensor lost on reflective masks filled in {} of {} frames, {} pixels (planes.fill)",
                 m.filled_frames, reports.size(), m.filled_pixels);
  result.trajectory = session.trajectory();
  if (dataset->has_ground_truth() && result.trajectory.size() < eval::kMinAlignedPoses) {
    spdlog::warn("run: no ATE: {} pose(s), the alignment needs at least {}", result.trajectory.size(),
                 eval::kMinAlignedPoses);
  } else if (dataset->has_ground_truth()) {
    io::Trajectory gt = dataset->ground_truth();
    if (gt.size() > n) gt.resize(n);
    m.ate_rmse_cm = eval::evaluate_trajectory(result.trajectory, gt).ate.rmse_cm;
  }
  const bool synth = dataset->format() == io::DatasetFormat::Synth;
  RunOutputs outputs(o.out, o.write_renders);
  if (synth) train.reflective_planes = reflective_gt_planes(io::synth_scene_file(dataset->root(), "planes.json"));
  for (const auto& [i, gt_color] : train_views) {
    const SessionView v = session.render(config.K, reports[i].T_wc);
    const ReflectiveTruth truth = synth ? read_reflective_truth(dataset->root(), i) : ReflectiveTruth{};
    train.add(v.C, gt_color, synth ? &truth : nullptr);
  }
  m.train = train.scores();
  for (size_t i : o.decomposition_frames) {
    if (i >= n) {
      spdlog::warn("run: --decomposition frame {} was not reached (stopped after {} frames)", i, n);
      continue;
    }
    const io::Frame f = dataset->load(i);
    outputs.decomposition(i, session.render(config.K, reports[i].T_wc), f.color);
  }
  if (synth && std::filesystem::exists(o.dataset / "novel")) {  // held-out views, never optimised on
    const auto novel = io::open_dataset(o.dataset / "novel");
    ScoreAccumulator held;
    held.reflective_planes = train.reflective_planes;
    for (size_t i = 0; i < novel->size(); ++i) {
      const io::Frame f = novel->load(i);
      if (!f.T_wc_gt) continue;
      const SessionView v = session.render(novel->intrinsics(), f.T_wc_gt->cast<float>());
      const ReflectiveTruth truth = read_reflective_truth(o.dataset / "novel", i);
      held.add(v.C, f.color, &truth);
      outputs.render("novel_" + std::to_string(i), v, &f.color);
    }
    m.held_out = held.scores();
  }
  if (!o.render_poses.empty())
    for (const NamedPose& p : read_render_poses(o.render_poses))
      outputs.render(p.name, session.render(config.K, p.T_wc), nullptr);

  TriangleMesh mesh;
  if (o.write_mesh || synth) mesh = session.mesh();
  if (synth && std::filesystem::exists(io::synth_scene_file(o.dataset, "mesh_gt.ply")) && !mesh.triangles.empty()) {
    const TriangleMesh gt = io::read_ply_mesh(io::synth_scene_file(o.dataset, "mesh_gt.ply"));
    const eval::ObservedMeshMetrics g = eval::evaluate_mesh_observed(mesh, gt, *dataset, n);
    m.accuracy_cm = g.whole.accuracy_cm;
    m.completion_whole_cm = g.whole.completion_cm;
    m.observed_fraction = g.observed_fraction;
    if (g.observed) {
      m.completion_cm = g.observed->completion_cm;
      m.completion_ratio = g.observed->completion_ratio;
    }
    spdlog::debug("run: {:.1f}% of the ground-truth surface observed; completion {} cm there, {:.2f} cm over the whole mesh",
                  100.0 * *m.observed_fraction, m.completion_cm ? fmt::format("{:.2f}", *m.completion_cm) : "-",
                  g.whole.completion_cm);
  }

  // --- files ---
  if (!o.out.empty()) {
    io::write_tum_trajectory(o.out / "trajectory.txt", result.trajectory);
    if (o.write_mesh && !mesh.triangles.empty()) outputs.mesh(mesh);
    if (o.write_gaussians) outputs.gaussians(session.base_gaussians(), session.reflection_gaussians(), session.reflective_planes());
    io::write_atomically(o.out / "metrics.json", [&](const std::filesystem::path& tmp) { std::ofstream(tmp) << metrics_json(m); });
    io::write_atomically(o.out / "timings.json", [&](const std::filesystem::path& tmp) {
      std::ofstream(tmp) << timings_json(t, config.device.to_string());
    });
  }
  return result;
}

std::string metrics_json(const RunMetrics& m) {
  nlohmann::ordered_json j;
  j["frames"] = m.frames;
  j["interrupted"] = m.interrupted;
  j["lost"] = m.lost;
  if (m.ate_rmse_cm) j["ate_rmse_cm"] = *m.ate_rmse_cm;
  j["ate_alignment"] = "rigid SE(3) Umeyama, no scale";
  auto scores = [](const ImageScores& s) {
    nlohmann::ordered_json x;
    x["views"] = s.views;
    x["psnr_db"] = s.psnr;
    x["ssim"] = s.ssim;
    x["psnr_reflective_db"] = s.psnr_reflective;
    x["reflective_pixels"] = s.reflective_pixels;
    x["reflective_planes"] = nlohmann::ordered_json::array();
    for (const PlaneScore& p : s.reflective_planes)
      x["reflective_planes"].push_back({{"id", p.id}, {"name", p.name}, {"pixels", p.pixels}, {"psnr_db", p.psnr}});
    return x;
  };
  j["train"] = scores(m.train);
  j["held_out"] = scores(m.held_out);
  if (m.accuracy_cm) {
    j["geometry"]["accuracy_cm"] = *m.accuracy_cm;
    if (m.completion_cm) {  // over the observed surface
      j["geometry"]["completion_cm"] = *m.completion_cm;
      j["geometry"]["completion_ratio_3cm"] = *m.completion_ratio;
    }
    j["geometry"]["completion_whole_mesh_cm"] = *m.completion_whole_cm;
    j["geometry"]["observed_fraction"] = *m.observed_fraction;
  }
  j["wall_s"] = m.wall_s;
  j["fps"] = m.fps;
  j["base_gaussians"] = m.base_gaussians;
  j["reflection_gaussians"] = m.reflection_gaussians;
  j["reflective_planes"] = m.reflective_planes;
  j["reflective_fill"] = {{"frames", m.filled_frames}, {"pixels", m.filled_pixels}};
  j["tsdf"] = {{"blocks", m.tsdf_blocks},
               {"resident_blocks", m.tsdf_resident_blocks},
               {"device_mb", double(m.tsdf_device_bytes) / 1e6},
               {"host_mb", double(m.tsdf_host_bytes) / 1e6}};
  return j.dump(2) + "\n";
}

std::string timings_json(const RunTimings& t, const std::string& device) {
  nlohmann::ordered_json j;
  j["device"] = device;
  j["unit"] = "ms per frame unless named per step";
  j["load"] = t.load_ms;
  j["load_wait"] = t.load_wait_ms;
  j["raycast"] = t.mean.raycast;
  j["preprocess"] = t.mean.preprocess;
  j["icp"] = t.mean.icp;
  j["orb"] = t.mean.orb;
  j["orb_mask"] = t.mean.mask;  // part of orb
  j["fuse"] = t.mean.fuse;
  j["fuse_stream"] = t.mean.stream;  // part of fuse (tsdf.stream_radius)
  j["identify"] = t.mean.identify;
  j["premapping"] = t.premapping_ms;
  j["mapping_wait_or_inline"] = t.mean.mapping;
  j["mapping_step_per_step"] = t.mapping_step_ms;
  j["mapping_raycast_per_step"] = t.mapping_raycast_ms;
  j["mapping_densify_per_step"] = t.mapping_densify_ms;
  j["mapping_optimise_per_step"] = t.mapping_optimise_ms;
  j["mapping_optimise_render_per_step"] = t.mapping_optimise.render;  // the four parts of mapping_optimise
  j["mapping_optimise_loss_per_step"] = t.mapping_optimise.loss;
  j["mapping_optimise_backward_per_step"] = t.mapping_optimise.backward;
  j["mapping_optimise_adam_per_step"] = t.mapping_optimise.adam;
  j["mapping_prune_per_step"] = t.mapping_prune_ms;
  j["mapping_steps"] = t.mapping_steps;
  j["mapping_iterations"] = t.mapping_iterations;
  j["mapping_waits"] = t.mapping_waits;
  j["schedule"] = t.schedule;
  j["rate_hz"] = t.rate_hz;
  j["input_latency_mean_ms"] = t.latency_mean_ms;  // with rate_hz > 0: from a frame's arrival to its pose
  j["input_latency_max_ms"] = t.latency_max_ms;
  j["process_total"] = t.mean.total;
  j["wall_per_frame"] = t.wall_ms_per_frame;
  j["fps"] = t.wall_ms_per_frame > 0 ? 1000.0 / t.wall_ms_per_frame : 0.0;
  return j.dump(2) + "\n";
}

}  // namespace rrg
