#pragma once
// Session internals shared by session.cpp (the schedule), session_queries.cpp (thread-safe
// renders, meshes, status) and session_snapshot.cpp (save / load). Not part of the API.
//
// Locks, always taken in this order when nested:
//   volume_mutex   the TSDF, a readers-writer lock: fusion (process thread) writes and holds it
//                  alone; raycasts (tracking, identification, the mapping thread's frames, renders
//                  from any thread), meshes, status and saves only read it and share it, so the
//                  mapping thread's raycasts run beside the process thread's;
//   state_mutex    trajectory, reports, status fields, reflective planes.
// The mapper publishes immutable snapshots for renders (core/slam/mapper.h), so rendering never
// waits for a mapping step.
#include "core/planes/plane_identification.h"
#include "core/slam/mapper.h"
#include "core/slam/session.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/model_source.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/tsdf_volume.h"

#include <atomic>
#include <set>
#include <span>
#include <condition_variable>
#include <mutex>
#include <shared_mutex>
#include <thread>

namespace rrg {

// ICP's model source with the raycast taken under the volume lock.
class LockedModelSource final : public ModelSource {
 public:
  LockedModelSource(const TsdfVolume& volume, const Intrinsics& K, std::shared_mutex& m) : inner_(volume, K), mutex_(m) {}
  IcpModel model_at(const Eigen::Isometry3f& T_wc) override {
    std::shared_lock lock(mutex_);  // the cached maps of inner_ are the process thread's alone
    return inner_.model_at(T_wc);
  }
  void invalidate() { inner_.invalidate(); }
  // The process thread's alone, as the cached maps (TsdfModelSource).
  void set_plane_ids(bool on, std::span<const int32_t> remap = {}) { inner_.set_plane_ids(on, remap); }
  const RaycastResult* last() const { return inner_.last(); }

 private:
  TsdfModelSource inner_;
  std::shared_mutex& mutex_;
};

// The mapping thread: runs one step at a time when asked; wait() blocks until it is idle.
class MappingWorker {
 public:
  MappingWorker() = default;
  ~MappingWorker() { stop(); }
  void start(std::function<void()> job);  // starts the thread on first use; job runs on it
  bool wait();                            // until the current job (if any) finished; whether one was running
  void stop();
  bool busy() const;

 private:
  void loop();
  std::thread thread_;
  mutable std::mutex m_;
  std::condition_variable cv_;
  std::function<void()> job_;
  bool running_ = false, quit_ = false;
  std::exception_ptr error_;
};

struct Session::Impl {
  explicit Impl(SessionConfig c, std::unique_ptr<SemanticCue> cue);

  // process() stages
  // Fills the fusion's reflection observation of this frame: I_k^g, the reflection mask and the
  // exposure gain (report.exposure_gain).
  // depth: D_k as tracked and fused (after the reflective fill); masks: the cue's masks of this
  // frame when the fill asked for them already (else identification asks the cue).
  void identify(const SessionFrame& frame, const DepthImage& depth, const std::vector<SemanticMask>* masks,
                const Eigen::Isometry3f& T_wc, FrameReport& report, DeviceImage<int32_t>& plane_ids,
                DeviceImage<uint8_t>& mask);
  void schedule_mapping(FrameReport& report);
  void thin_queue();
  MappingContext mapping_context();
  RaycastResult locked_raycast(const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                               RaycastOutputs outputs = RaycastOutputs::all()) const;
  // C_r for the tracking mask, exact where its mean RGB stays <= stop_mean (the mask's threshold)
  ReflectionView render_reflection(const Eigen::Isometry3f& T_wc, float stop_mean);
  std::vector<int32_t> unmodelled_planes(const MapSnapshot* snap) const;
  static bool mask_can_show(const MapSnapshot* snap, std::span<const int32_t> unmodelled);
  std::vector<int32_t> remap_copy() const {
    std::lock_guard lock(state_mutex);
    return remap;
  }

  SessionConfig config;
  Intrinsics K;
  mutable std::shared_mutex volume_mutex;
  TsdfVolume volume;
  LockedModelSource model;
  Tracker tracker;
  PlaneIdentifier identifier;
  GaussianMapper mapper;
  std::unique_ptr<MaskSource> masks;  // icp+orb+mask: rendered C_r
  DeviceImage<int32_t> mask_plane_ids;  // I at the ICP pose for the mask (render_reflection)
  Buffer<uint64_t> mask_zbuffer;        // its warp's scratch
  DeviceImage<float> given_normal_depth;  // with given poses: the filtered D_k fusion's normals come from
  MappingWorker worker;

  // the schedule
  int64_t frames = 0, fused = 0, lost = 0, last_index = -1;
  int64_t fused_at_step = 0;  // `fused` when the last mapping step was scheduled (live: the frames a step covers)
  std::vector<MappingFrame> pending;  // fused frames not yet handed to the mapper
  std::vector<bool> pending_keyframe;

  mutable std::mutex state_mutex;
  std::vector<int32_t> remap;          // plane id -> canonical id (identification)
  size_t tracker_keyframes = 0, global_planes = 0;
  io::Trajectory trajectory;
  std::vector<FrameReport> reports;
  std::vector<ReflectivePlane> reflective;
  // The last fill's surfaces (world frame), for frames without masks (planes.fill). Saved in
  // snapshots (the continuation section).
  std::vector<FillRegion> fill_regions;
  // Planes a semantic cue calls reflective whose vote is still open (undecided_candidates), kept out
  // of the tracking mask's features with tracking.orb.mask_unmodelled; pre-mapping thread.
  std::set<int> undecided;
  MappingSummary mapping;
  std::atomic<uint64_t> map_version{0};
  TrackingState state = TrackingState::Ok;
  Eigen::Isometry3f T_last = Eigen::Isometry3f::Identity();
};

}  // namespace rrg
