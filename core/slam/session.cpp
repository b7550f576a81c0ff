// The session's schedule (paper §4): pre-mapping per frame, identification every N_p frames,
// mapping every N_o frames on the mapping thread (or inline with config.sync).
#include "core/slam/session_impl.h"

#include "core/planes/exposure_gain.h"
#include "core/planes/remote_segmenter.h"
#include "core/planes/semantic_labels.h"
#include "core/tracking/preprocess.h"
#include "core/tsdf/raycast_warp.h"
#include "core/tsdf/tsdf_integrate.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <stdexcept>

namespace rrg {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::unique_ptr<SemanticCue> cue_from_config(const SessionConfig& c) {
  const std::vector<std::string> prompts = c.prompts.empty() ? default_prompts() : c.prompts;
  if (c.semantics == "none") return make_no_semantics();
  if (c.semantics == "labels") {
    CategoryTable table;
    for (const auto& [id, name] : c.categories) table.names[id] = name;
    return make_label_semantics(std::move(table), prompts);
  }
  RemoteSegmenterOptions o;
  o.address = c.remote_address;
  o.prompts = prompts;
  return make_remote_semantics(o);
}

SessionConfig validated(SessionConfig c) {
  c.validate();
  return c;
}

}  // namespace

// --- the mapping thread --------------------------------------------------------------------------

void MappingWorker::start(std::function<void()> job) {
  std::unique_lock lock(m_);
  cv_.wait(lock, [&] { return !running_; });
  if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
  job_ = std::move(job);
  running_ = true;
  cv_.notify_all();
}

bool MappingWorker::wait() {
  std::unique_lock lock(m_);
  const bool was_running = running_;
  cv_.wait(lock, [&] { return !running_; });
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return was_running;
}

bool MappingWorker::busy() const {
  std::lock_guard lock(m_);
  return running_;
}

void MappingWorker::stop() {
  {
    std::unique_lock lock(m_);
    cv_.wait(lock, [&] { return !running_; });
    quit_ = true;
    cv_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
}

void MappingWorker::loop() {
  std::unique_lock lock(m_);
  for (;;) {
    cv_.wait(lock, [&] { return quit_ || (running_ && job_); });
    if (quit_ && !running_) return;
    auto job = std::move(job_);
    job_ = nullptr;
    lock.unlock();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    if (error) error_ = error;
    running_ = false;
    cv_.notify_all();
  }
}

// --- construction ----------------------------------------------------------------------------------

Session::Impl::Impl(SessionConfig c, std::unique_ptr<SemanticCue> cue)
    : config(validated(std::move(c))),
      K(config.K),
      volume(config.tsdf_params(), config.device),
      model(volume, K,
            [this](const Eigen::Isometry3f& T_wc, const std::function<void()>& read) {
              read_view(K, T_wc, [&] {
                read();
                return 0;
              });
            }),
      tracker(config.tracking_params(), K, config.device),
      identifier(config.planes, cue ? std::move(cue) : cue_from_config(config)),
      mapper(config.mapping, K, config.device) {
  if (config.tracking.mode == TrackingMode::IcpOrbMask && !config.gt_poses)
    masks = std::make_unique<RenderedReflectionMasks>(
        [this](size_t, const Eigen::Isometry3f& T_wc, float threshold) { return render_reflection(T_wc, threshold); },
        config.tracking.orb.mask_threshold);
}

Session::Session(SessionConfig config, std::unique_ptr<SemanticCue> cue)
    : impl_(std::make_unique<Impl>(std::move(config), std::move(cue))) {
  if (const float r = impl_->config.stream_radius, reach = view_reach(impl_->K, impl_->config.tsdf_params());
      r > 0.0f && r < reach)
    spdlog::warn("session: tsdf.stream_radius {:.2f} m is less than the {:.2f} m a frame reaches (tsdf.max_depth {:.2f} m "
                 "along the image corners): blocks in view go to host memory and back every frame; {:.2f} m or more "
                 "avoids that",
                 r, reach, impl_->config.tsdf.max_depth, reach);
  spdlog::debug("session: {}x{} on {}, tracking {}, semantics {}, mapping every {} frames ({})", impl_->K.width,
                impl_->K.height, impl_->config.device.to_string(), to_string(impl_->config.tracking.mode),
                impl_->identifier.cue().name(), impl_->config.mapping_period, to_string(impl_->config.schedule()));
}

Session::~Session() {
  if (impl_) {
    try {
      impl_->worker.wait();
    } catch (const std::exception& e) {
      spdlog::error("session: mapping step failed while closing: {}", e.what());
    }
    impl_->worker.stop();
  }
}

const SessionConfig& Session::config() const { return impl_->config; }

// --- helpers ----------------------------------------------------------------------------------------

RaycastResult Session::Impl::locked_raycast(const Intrinsics& K_, const Eigen::Isometry3f& T_wc,
                                            RaycastOutputs outputs, Reader who) const {
  const std::vector<int32_t> ids = remap_copy();
  return read_view(K_, T_wc, [&] { return raycast(volume, K_, T_wc, ids, outputs); }, who);
}

// C_r at the ICP pose for the tracking mask (§4.1.2): pass 3 over the plane-id map only, each
// pixel composited until the mask's test mean RGB > threshold is decided (the mask is the same).
// With tracking.orb.mask_unmodelled also the pixels of the planes whose reflection is not modelled
// yet (unmodelled_planes), from the same raycast's plane-id map.
ReflectionView Session::Impl::render_reflection(const Eigen::Isometry3f& T_wc, float stop_mean) {
  const auto snap = mapper.snapshot();
  const bool gaussians = snap && snap->reflection.size() > 0;
  const std::vector<int32_t> unknown = unmodelled_planes(snap.get());
  ReflectionView view;
  if (!mask_can_show(snap.get(), unknown)) {
    view.color = ColorImage(K.width, K.height, Color::Zero());
    return view;
  }
  // At 1/f of the frame's size (tracking.orb.mask_downsample), then each pixel to its f x f block.
  const int f = config.tracking.orb.mask_downsample;
  const Intrinsics Ks = f == 1 ? K : K.scaled(std::max(1, K.width / f), std::max(1, K.height / f));
  // I at T_wc: the ICP model's raycast at T_{k−1} warped there (tracking.orb.mask_warp; the model
  // keeps I while the mask can show something), else a raycast there (the first frame, or a model
  // raycast without I).
  const RaycastResult* source = config.tracking.orb.mask_warp ? model.last() : nullptr;
  if (source && source->plane_ids.width() > 0) {
    warp_plane_ids(*source, Ks, T_wc, mask_plane_ids, mask_zbuffer);
  } else {
    RaycastResult rc = locked_raycast(Ks, T_wc, RaycastOutputs{.color = false, .reflection = true, .normals = false});
    mask_plane_ids = std::move(rc.plane_ids);
  }
  const ColorImage C_r = gaussians ? mapper.render_reflection(RenderCamera{Ks, T_wc}, mask_plane_ids, stop_mean)
                                   : ColorImage(Ks.width, Ks.height, Color::Zero());
  MaskImage unmodelled;
  if (!unknown.empty()) {
    const Image<int32_t> I = mask_plane_ids.to_host();
    unmodelled = MaskImage(Ks.width, Ks.height, 0);
    for (size_t i = 0; i < I.size(); ++i)
      unmodelled[i] = I[i] > 0 && std::binary_search(unknown.begin(), unknown.end(), I[i]) ? 1 : 0;
  }
  if (f == 1) return ReflectionView{C_r, std::move(unmodelled)};
  view.color = ColorImage(K.width, K.height);
  if (!unmodelled.empty()) view.unmodelled = MaskImage(K.width, K.height, 0);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const int us = std::min(u / f, Ks.width - 1), vs = std::min(v / f, Ks.height - 1);
      view.color(u, v) = C_r(us, vs);
      if (!unmodelled.empty()) view.unmodelled(u, v) = unmodelled(us, vs);
    }
  return view;
}

// The planes whose reflection the model cannot render yet, sorted: the semantic candidates whose
// vote is open, and the accepted planes (L_ref) without reflection Gaussians in `snap` (null: none
// yet). None without reflections (the base-only ablation keeps the paper's mask, which is then
// empty) or with tracking.orb.mask_unmodelled off.
std::vector<int32_t> Session::Impl::unmodelled_planes(const MapSnapshot* snap) const {
  const std::span<const int32_t> rendered =
      snap ? std::span<const int32_t>(snap->reflection_planes) : std::span<const int32_t>{};
  std::vector<int32_t> ids;
  if (!config.tracking.orb.mask_unmodelled || !config.mapping.reflections) return ids;
  ids.assign(undecided.begin(), undecided.end());
  {
    std::lock_guard lock(state_mutex);
    for (const ReflectivePlane& p : reflective)
      if (!std::binary_search(rendered.begin(), rendered.end(), p.id)) ids.push_back(p.id);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

// Whether the tracking mask can hold a pixel: reflection Gaussians render, or a plane is unmodelled.
bool Session::Impl::mask_can_show(const MapSnapshot* snap, std::span<const int32_t> unmodelled) {
  return (snap && snap->reflection.size() > 0) || !unmodelled.empty();
}

MappingContext Session::Impl::mapping_context() {
  MappingContext ctx;
  std::vector<int32_t> ids;  // the remap table of the step's raycasts, taken with its planes
  {
    std::lock_guard lock(state_mutex);
    ids = remap;
    if (config.mapping.reflections) {
      for (const ReflectivePlane& p : reflective) ctx.planes.push_back({p.id, p.plane});
      ctx.remap = remap;
    }
  }
  // The mapper reads D_t, C_t, I, R and C_var (to_inputs, densify), never V* or N*. The raycasts
  // keep the table taken here whichever thread runs them: a live step prepares on the mapping
  // thread, after identifications that may have merged planes since.
  ctx.raycast = [this, ids = std::move(ids)](const Intrinsics& K_, const Eigen::Isometry3f& T_wc) {
    return read_view(K_, T_wc, [&] {
      return raycast(volume, K_, T_wc, ids, RaycastOutputs{.color = true, .reflection = true, .normals = false});
    });
  };
  return ctx;
}

// Plane identification (§4.1.3) at the tracked pose, before this frame is fused.
void Session::Impl::identify(const SessionFrame& frame, const DepthImage& depth, const std::vector<SemanticMask>* masks,
                             const Eigen::Isometry3f& T_wc, FrameReport& report, DeviceImage<int32_t>& plane_ids,
                             DeviceImage<uint8_t>& mask) {
  const auto t0 = Clock::now();
  // C_var for the check; C_t and D_t only for the exposure gain (the identification's colour edges
  // are the input's).
  const bool exposure = config.planes.exposure_compensation;
  const RaycastResult rc = locked_raycast(K, T_wc, RaycastOutputs{.color = exposure, .reflection = true, .normals = false});
  const Image<float> cvar = rc.color_variance.to_host();
  if (exposure) {
    const ExposureGain g = estimate_exposure_gain(frame.color, depth, rc, config.tsdf.truncation);
    report.exposure_gain = g.gain;
    spdlog::debug("frame {}: exposure gain {:.3f} over {} pixels{}", frame.index, g.gain, g.pixels,
                  g.estimated ? "" : " (too few: 1)");
  }
  IdentificationFrame f{&depth, &frame.color, frame.labels ? &*frame.labels : nullptr, K, T_wc, frame.index,
                        config.tsdf.voxel_size, masks};
  if (identifier.cue().name() == "labels" && !frame.labels) f.labels = nullptr;
  IdentificationResult r = identifier.identify(f, cvar);
  undecided = undecided_candidates(undecided, r, identifier.vote(), identifier.table(),
                                   identifier.cue().every_plane_is_candidate());
  plane_ids = DeviceImage<int32_t>::from_host(r.global_map, config.device);
  mask = DeviceImage<uint8_t>::from_host(r.reflection_mask, config.device);
  std::vector<ReflectivePlane> accepted;
  for (int id : identifier.vote().lookup_table()) {
    const GlobalPlane* g = identifier.table().find(id);
    if (!g) continue;
    accepted.push_back({g->id, Eigen::Vector4f(g->plane.n.x(), g->plane.n.y(), g->plane.n.z(), g->plane.d)});
  }
  {
    std::lock_guard lock(state_mutex);
    reflective = std::move(accepted);
    remap = std::move(r.remap);
    global_planes = identifier.table().live_ids().size();
  }
  report.identified = true;
  report.times.identify += ms_since(t0);
}

// Live: the queue bounded (thin_live_queue, mapping_schedule.h); the dropped frames are counted.
void Session::Impl::thin_queue() {
  if (pending.size() <= size_t(kLiveQueueSteps) * size_t(config.mapping_period)) return;  // the usual case: no copy
  const std::vector<size_t> keep = thin_live_queue(pending_keyframe, config.mapping_period);
  if (keep.size() == pending.size()) return;
  std::vector<MappingFrame> frames;
  std::vector<bool> flags;
  for (size_t i : keep) {
    frames.push_back(std::move(pending[i]));
    flags.push_back(pending_keyframe[i]);
  }
  const int64_t dropped = int64_t(pending.size() - keep.size());
  pending = std::move(frames);
  pending_keyframe = std::move(flags);
  std::lock_guard lock(state_mutex);
  mapping.thinned += dropped;
}

// Hands the fused frames to the mapper and runs a step: inline (sync) or on the mapping thread.
void Session::Impl::schedule_mapping(FrameReport& report) {
  const auto t0 = Clock::now();
  // The frames since the last step go to the mapper, and the next step is prepared here: its frames
  // selected and pass 1 raycast on this (pre-mapping) thread, from the TSDF as fused up to this
  // frame, while a running step still optimises (it chose its frames when it was prepared). Then
  // the step's remaining work waits for the running one and goes to the mapping thread (inline
  // with --sync, in the same order). Live, no step runs here (mapping_due), so nothing overlaps the
  // preparation: it goes to the mapping thread too, and pre-mapping goes on at once.
  for (size_t i = 0; i < pending.size(); ++i) mapper.add_frame(std::move(pending[i]), pending_keyframe[i]);
  pending.clear();
  pending_keyframe.clear();
  MappingContext ctx = mapping_context();
  // Live: the step's iterations follow the frames fused since the step before (mapping_schedule.h).
  if (config.schedule() == MappingSchedule::Live)
    ctx.iterations = live_step_iterations(config.mapping.iterations, config.mapping_period, fused - fused_at_step,
                                          config.live_step_scale);
  fused_at_step = fused;
  const bool prepare_here = config.schedule() != MappingSchedule::Live;
  std::shared_ptr<GaussianMapper::Prepared> prepared = prepare_here ? mapper.prepare(ctx) : nullptr;
  std::exception_ptr failed;  // of the running step: reported after this one starts (its frames are consumed)
  bool waited = false;
  try {
    waited = worker.wait();
  } catch (...) {
    failed = std::current_exception();
  }
  if (waited) {
    std::lock_guard lock(state_mutex);
    ++mapping.waits;
  }
  auto job = [this, ctx, prepared = std::move(prepared)]() mutable {
    if (!prepared) prepared = mapper.prepare(ctx);  // live
    const MappingStats s = mapper.run(std::move(prepared), ctx);
    std::lock_guard lock(state_mutex);
    ++mapping.steps;
    mapping.iterations += s.iterations;
    mapping.ms_total += s.ms_total;
    mapping.ms_raycast += s.ms_raycast;
    mapping.ms_densify += s.ms_densify;
    mapping.ms_optimise += s.ms_optimise;
    mapping.optimise += s.optimise;
    mapping.ms_prune += s.ms_prune;
    mapping.last_loss = s.loss;
    mapping.base_gaussians = int64_t(mapper.snapshot() ? mapper.snapshot()->base.size() : 0);
    mapping.reflection_gaussians = int64_t(mapper.snapshot() ? mapper.snapshot()->reflection.size() : 0);
    map_version.fetch_add(1);
  };
  if (config.sync) {
    job();
  } else {
    worker.start(std::move(job));
  }
  report.mapping_started = true;
  report.times.mapping = ms_since(t0);
  if (failed) std::rethrow_exception(failed);
}

// --- process -----------------------------------------------------------------------------------------

FrameReport Session::process(const SessionFrame& frame) {
  Impl& s = *impl_;
  const auto t0 = Clock::now();
  if (frame.color.width() != s.K.width || frame.color.height() != s.K.height)
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": colour is " + std::to_string(frame.color.width()) +
                                "x" + std::to_string(frame.color.height()) + ", the session expects " +
                                std::to_string(s.K.width) + "x" + std::to_string(s.K.height));
  if (frame.depth.width() != s.K.width || frame.depth.height() != s.K.height)
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": depth is " + std::to_string(frame.depth.width()) +
                                "x" + std::to_string(frame.depth.height()) + ", the session expects " +
                                std::to_string(s.K.width) + "x" + std::to_string(s.K.height));
  if (frame.labels && (frame.labels->width() != s.K.width || frame.labels->height() != s.K.height))
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": label image size differs from the session's");
  if (frame.index <= s.last_index)
    throw std::invalid_argument("frame id " + std::to_string(frame.index) + " is not above the last one (" +
                                std::to_string(s.last_index) + ")");
  if (s.config.gt_poses && !frame.pose)
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": gt_poses is set but the frame has no pose");

  FrameReport report;
  report.index = frame.index;
  report.timestamp = frame.timestamp;

  // 0. depth the sensor lost on reflective masks, filled from the plane around them for
  // identification, fusion and the mapper (planes.fill, core/planes/reflective_fill.h): on the
  // frames whose masks the cue gives anyway (identification frames) or at no cost (labels).
  const bool identify_due = s.fused % s.config.plane_period == 0;
  std::optional<std::vector<SemanticMask>> masks;
  std::optional<ReflectiveFillResult> mask_fill;  // kept for its regions once the pose is known
  DepthImage filled, tracked;  // D_k filled for the map; D_k for tracking
  const DepthImage* D_k = &frame.depth;
  const SemanticCue& cue = s.identifier.cue();
  if (s.config.planes.fill.enabled && !cue.every_plane_is_candidate() &&
      (identify_due || (cue.masks_with_every_frame() && frame.labels))) {
    const auto tf = Clock::now();
    masks = s.identifier.semantic_masks({&frame.depth, &frame.color, frame.labels ? &*frame.labels : nullptr, s.K,
                                         Eigen::Isometry3f::Identity(), frame.index, s.config.tsdf.voxel_size});
    filled = frame.depth;
    mask_fill = fill_reflective_depth(filled, *masks, s.K, s.config.planes.fill_params());
    report.filled_pixels = mask_fill->pixels;
    for (const ReflectiveFillMask& m : mask_fill->masks)
      spdlog::debug("frame {}: {}", frame.index, describe(m));
    report.times.identify = ms_since(tf);
  }
  // Tracking leaves out the pixels the fill writes (lost, or seen through the glass), so that a
  // plane fitted a little off from frame to frame (a mask short of the glass takes in its frame)
  // does not move the pose, and the depth seen through the glass is no outlier of ICP's: those of
  // the masks' own fill, and those the carried regions will fill after tracking, found here at the
  // predicted pose (the fill itself waits for the tracked one).
  const bool fill_pending = s.config.planes.fill.enabled && ((mask_fill && mask_fill->pixels > 0) ||
                                                              (s.config.planes.fill.carry && !s.fill_regions.empty()));
  if (fill_pending && !s.config.gt_poses) {
    const auto tf = Clock::now();
    MaskImage blank = mask_fill ? mask_fill->filled : MaskImage(s.K.width, s.K.height, 0);
    if (s.config.planes.fill.carry && !s.fill_regions.empty() && s.frames > 0) {
      const Eigen::Isometry3f T_pred = frame.pose ? *frame.pose : s.tracker.predicted_pose();
      const ReflectiveFillParams params = s.config.planes.fill_params();
      DepthImage probe = mask_fill ? filled : frame.depth;
      if (mask_fill) {
        ReflectiveFillResult failed = *mask_fill;
        fill_failed_masks_from_regions(probe, failed, *masks, s.fill_regions, s.K, T_pred, params, blank);
      }
      const ReflectiveFillResult fr = fill_from_regions(probe, s.fill_regions, s.K, T_pred, params);
      for (size_t i = 0; i < blank.size(); ++i) blank[i] |= fr.filled[i];
    }
    if (std::any_of(blank.pixels().begin(), blank.pixels().end(), [](uint8_t b) { return b != 0; })) {
      tracked = frame.depth;
      for (size_t i = 0; i < tracked.size(); ++i)
        if (blank[i]) tracked[i] = 0.0f;
      D_k = &tracked;
    }
    report.times.identify += ms_since(tf);
  }
  s.frame_depth.upload(*D_k, s.config.device);
  s.frame_color.upload(frame.color, s.config.device);
  const DeviceImage<float>& depth = s.frame_depth;
  const DeviceImage<Color>& color = s.frame_color;

  // 1. tracking (§4.1.2), or the given pose. Mapping keyframes are the tracker's keyframes (the
  // first frame included); with given poses, every N_o-th fused frame.
  bool keyframe = false;
  if (s.config.gt_poses) {
    keyframe = s.fused % s.config.mapping_period == 0;
    report.T_wc = *frame.pose;
    report.state = TrackingState::Ok;
  } else {
    if (s.frames == 0 && frame.pose) s.tracker.set_initial_pose(*frame.pose);
    else if (frame.pose) s.tracker.set_pose_prior(*frame.pose);
    if (s.frames > 0) {
      const auto tr = Clock::now();
      // The model keeps I for the tracking mask's warp while the mask can show something (else
      // render_reflection returns before it needs I; should that change before the mask is
      // asked for, it raycasts).
      bool warp = s.masks && s.config.tracking.orb.mask_warp;
      if (warp) {
        const auto snap = s.mapper.snapshot();
        warp = s.mask_can_show(snap.get(), s.unmodelled_planes(snap.get()));
      }
      s.model.set_plane_ids(warp, s.remap);
      s.model.model_at(s.T_last);
      report.times.raycast = ms_since(tr);
    }
    const TrackResult r = s.tracker.track({size_t(frame.index), &frame.color, D_k, &depth}, s.model, s.masks.get());
    report.T_wc = r.T_wc;
    report.state = r.state;
    report.note = r.note;
    report.times.preprocess = r.ms_preprocess;
    report.times.icp = r.ms_icp;
    report.times.orb = r.ms_orb;
    report.times.mask = r.ms_mask;
    report.tracking_mask_pixels = r.mask_pixels;
    keyframe = r.keyframe || r.first;
  }
  if (D_k == &tracked) D_k = &frame.depth;  // the map takes the frame, filled below, not what tracking saw

  // The depth fusion takes its normals from: the tracker's filtered D_k, or with given poses the
  // same filter run here (at 640x480 the raw depth's normals are noise; Tracker::normal_depth()).
  const DeviceImage<float>* frame_normal_depth =
      !s.config.gt_poses ? s.tracker.normal_depth()
      : filter_depth_into(s.given_normal_depth, depth, s.tracker.params().preprocess) ? &s.given_normal_depth
                                                                                        : nullptr;

  // The fill, between frames with masks: the surfaces earlier fills found (world regions) at the
  // tracked pose, for fusion and the mapper (tracking saw this frame as it came, less the pixels its
  // masks filled; ICP's association drops points behind the model's surface). On a frame with masks, a
  // mask that failed the ring's test (a segmenter's mask short of the glass or over its frame) takes
  // the plane of the region it lies on, and the masks filled update the regions; the regions no mask
  // showed again then fill what is still lost in their footprints (glass the segmenter missed), as
  // on frames without masks. (A region a mask filled is not applied over it: its footprint, dilated
  // by a cell, would press the wall around the glass onto a plane fitted a little in front of it.)
  // What fusion takes on a filled frame: the frame with the fill written in, and the filtered
  // depth its normals come from, filled the same way.
  std::optional<DeviceImage<float>> fuse_depth, fuse_normal_depth;
  if (report.state != TrackingState::Lost && fill_pending) {
    const auto tf = Clock::now();
    const ReflectiveFillParams params = s.config.planes.fill_params();
    DepthImage carried = mask_fill ? std::move(filled) : frame.depth;  // the masks' fill, if any
    MaskImage written = mask_fill ? mask_fill->filled : MaskImage(s.K.width, s.K.height, 0);
    int64_t pixels = 0;  // beyond the masks' own fill
    if (s.config.planes.fill.carry && mask_fill) {
      // A mask the sensor kept refutes a carried region that would write over it: this frame's
      // depth, not an earlier fill, decides there (drop_refuted_regions).
      if (const size_t dropped =
              drop_refuted_regions(s.fill_regions, *mask_fill, *masks, frame.depth, s.K, report.T_wc, params))
        spdlog::debug("frame {}: {} carried fill region(s) dropped: a mask's own depth refutes them", frame.index, dropped);
    }
    size_t unseen = s.fill_regions.size();  // the regions no mask of this frame showed again come first
    if (s.config.planes.fill.carry) {
      if (mask_fill) {
        pixels += fill_failed_masks_from_regions(carried, *mask_fill, *masks, s.fill_regions, s.K, report.T_wc, params, written);
        if (mask_fill->pixels > 0)
          unseen = merge_fill_regions(
              s.fill_regions, fill_regions(*mask_fill, *masks, s.K, report.T_wc, s.config.planes.table.cell_size),
              s.config.planes.region_match());
      }
      if (unseen > 0) {
        const ReflectiveFillResult fr =
            fill_from_regions(carried, std::span(s.fill_regions).first(unseen), s.K, report.T_wc, params);
        pixels += fr.pixels;
        for (size_t i = 0; i < written.size(); ++i) written[i] |= fr.filled[i];
      }
    }
    report.filled_pixels += pixels;
    if (report.filled_pixels > 0) {
      filled = std::move(carried);
      fuse_depth = DeviceImage<float>::from_host(filled, s.config.device);
      // The filtered depth is of what tracking saw: pixels it left out and the fill did not write
      // have no normal there, so they are not fused (what the glass showed).
      if (const DeviceImage<float>* f = frame_normal_depth) {
        DepthImage smooth = f->to_host();
        copy_filled_depth(filled, written, smooth);
        fuse_normal_depth = DeviceImage<float>::from_host(smooth, s.config.device);
      }
      D_k = &filled;
    }
    report.times.identify += ms_since(tf);
  }

  // 2. identification every N_p frames (§4.1.3), then 3. fusion (§4.1.4)
  if (report.state != TrackingState::Lost) {
    DeviceImage<int32_t> plane_ids;
    DeviceImage<uint8_t> mask;
    const bool identify = identify_due;  // (decided before tracking: the fill asks for its masks)
    // The glass a mask stopped short of, which the fill found beyond it, is the mirror's too: its
    // reflections belong in the predicted reflection mask (R), not in the base, nor under ORB.
    if (identify && mask_fill && masks) add_glass_beyond(*mask_fill, *masks);
    if (identify) s.identify(frame, *D_k, masks ? &*masks : nullptr, report.T_wc, report, plane_ids, mask);
    const auto tf = Clock::now();
    {
      std::unique_lock lock(s.volume_mutex);  // the one writer
      const ReflectionObservation obs{&plane_ids, &mask, s.remap, report.exposure_gain};  // remap: this thread's
      // The sensor's D_k with the normals of the bilateral-filtered one: at fine resolutions the raw
      // depth's noise exceeds the pixel spacing and its normals (point-to-plane sdf, grazing test)
      // would drop the surface, while filtered positions differ from view to view (docs/tracking.md
      // "Positions from the sensor, normals from the filter"); with the filter off, the depth's own.
      const DeviceImage<float>* normal_depth =
          fuse_depth ? (fuse_normal_depth ? &*fuse_normal_depth : nullptr) : frame_normal_depth;
      integrate(s.volume, fuse_depth ? *fuse_depth : depth, color, s.K, report.T_wc, identify ? &obs : nullptr,
                normal_depth);
      // tsdf.stream_radius: the blocks far from the camera to host memory (fusion brings back
      // those a later frame touches, read_view those a view needs).
      if (s.config.stream_radius > 0.0f) {
        const auto ts = Clock::now();
        s.volume.stream_out(report.T_wc.translation(), s.config.stream_radius);
        report.times.stream = ms_since(ts);
      }
    }
    s.model.invalidate();
    report.times.fuse = ms_since(tf);
    report.fused = true;
    ++s.fused;
    s.map_version.fetch_add(1);
    s.pending.push_back(MappingFrame{frame.index, report.T_wc, frame.color, *D_k});
    s.pending_keyframe.push_back(keyframe);
    if (s.config.schedule() == MappingSchedule::Live) s.thin_queue();
    // 4. a mapping step every N_o fused frames (§4.2; live: once N_o are queued and none runs)
    if (mapping_due(s.config.schedule(), s.config.mapping_period, s.fused, s.pending.size(), s.worker.busy()))
      s.schedule_mapping(report);
  } else {
    ++s.lost;
  }
  ++s.frames;
  s.last_index = frame.index;
  s.T_last = report.T_wc;
  report.map_version = s.map_version.load();
  report.times.total = ms_since(t0);
  {
    std::lock_guard lock(s.state_mutex);
    s.mapping.queued = int64_t(s.pending.size());
    s.trajectory.push_back({frame.timestamp, report.T_wc.cast<double>()});
    s.reports.push_back(report);
    s.state = report.state;
    s.tracker_keyframes = s.tracker.keyframes().size();
  }
  return report;
}

void Session::flush() { impl_->worker.wait(); }

void Session::finish() {
  Impl& s = *impl_;
  s.worker.wait();
  if (!s.pending.empty() || s.config.final_steps > 0) {
    FrameReport dummy;
    if (!s.pending.empty()) s.schedule_mapping(dummy);
    s.worker.wait();
    for (int i = 0; i < s.config.final_steps; ++i) {
      s.schedule_mapping(dummy);
      s.worker.wait();
    }
  }
  std::lock_guard lock(s.state_mutex);
  s.mapping.queued = int64_t(s.pending.size());
}

}  // namespace rrg
