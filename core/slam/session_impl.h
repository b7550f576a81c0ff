#pragma once
// Session internals shared by session.cpp (the schedule), session_queries.cpp (thread-safe
// renders, meshes, status) and session_snapshot.cpp (save / load). Not part of the API.
//
// Locks, always taken in this order when nested:
//   volume_mutex   the TSDF, a readers-writer lock: fusion (process thread) writes and holds it
//                  alone; raycasts (tracking, identification, the mapping thread's frames, renders
//                  from any thread), meshes, status and saves only read it and share it, so the
//                  mapping thread's raycasts run beside the process thread's. With streaming
//                  (tsdf.stream_radius) fusion also streams out the blocks far from the camera, and
//                  a reader that needs streamed-out blocks takes the lock alone to bring them back
//                  and send them out again (read_view, read_blocks);
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
#include "core/tsdf/view_frustum.h"

#include <atomic>
#include <set>
#include <span>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <shared_mutex>
#include <thread>

namespace rrg {

// ICP's model source with the raycast taken under the volume lock, with the blocks it sees resident.
class LockedModelSource final : public ModelSource {
 public:
  // locked(T_wc, read) runs read() under the volume lock with the view of (K, T_wc) resident.
  using Locked = std::function<void(const Eigen::Isometry3f&, const std::function<void()>&)>;
  LockedModelSource(const TsdfVolume& volume, const Intrinsics& K, Locked locked)
      : inner_(volume, K), locked_(std::move(locked)) {}
  IcpModel model_at(const Eigen::Isometry3f& T_wc) override {
    IcpModel m;  // the cached maps of inner_ are the process thread's alone
    locked_(T_wc, [&] { m = inner_.model_at(T_wc); });
    return m;
  }
  void invalidate() { inner_.invalidate(); }
  // The process thread's alone, as the cached maps (TsdfModelSource).
  void set_plane_ids(bool on, std::span<const int32_t> remap = {}) { inner_.set_plane_ids(on, remap); }
  const RaycastResult* last() const { return inner_.last(); }

 private:
  TsdfModelSource inner_;
  Locked locked_;
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
  // Who reads a streaming TSDF (read_view below): the session itself, or a client's query.
  enum class Reader { Session, Client };
  RaycastResult locked_raycast(const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                               RaycastOutputs outputs = RaycastOutputs::all(), Reader who = Reader::Session) const;
  // Streaming (tsdf.stream_radius; docs/tsdf.md "Streaming in a session"). Runs read() under the
  // volume lock with every block a camera K at T_wc may read resident (ViewFrustum). The lock is
  // shared when they are (always without streaming); else it is taken alone, the streamed-out
  // ones come back for read() and go out again after it, so a read leaves the volume's residency
  // as it found it. Should read() throw, they stay until the next frame streams out.
  //
  // Who reads decides what happens to the pool's size: a session's own reads (tracking,
  // identification, mapping keyframes) come back every few frames, so the room they grew is kept
  // (the pool holds what the session's work needs, and regrowing it each time would copy it each
  // time); a client's read (render, mesh) gives back the room it grew, so no request can enlarge the
  // session's device memory for good.
  template <class Read>
  auto read_view(const Intrinsics& K_view, const Eigen::Isometry3f& T_wc, Read&& read,
                 Reader who = Reader::Session) const {
    const ViewFrustum frustum(K_view, T_wc, volume.params());
    return read_with(read, [&](const Eigen::Vector3i& b) { return frustum.may_read(b); }, who);
  }
  // The same for meshing the listed blocks: they and the blocks whose voxels their cubes read
  // (the +x, +y, +z neighbours) resident.
  template <class Read>
  auto read_blocks(std::span<const Eigen::Vector3i> blocks, Read&& read, Reader who) const {
    std::vector<uint64_t> needed;
    needed.reserve(blocks.size() * 8);
    for (const Eigen::Vector3i& b : blocks)
      for (int d = 0; d < 8; ++d) {
        const Eigen::Vector3i n = b + Eigen::Vector3i(d & 1, (d >> 1) & 1, (d >> 2) & 1);
        needed.push_back(block_key(n.x(), n.y(), n.z()));
      }
    std::sort(needed.begin(), needed.end());
    return read_with(read, [&](const Eigen::Vector3i& b) {
      return std::binary_search(needed.begin(), needed.end(), block_key(b.x(), b.y(), b.z()));
    }, who);
  }
  template <class Read, class Needs>
  auto read_with(Read& read, const Needs& needs, Reader who) const {
    {
      std::shared_lock lock(volume_mutex);
      if (volume.num_host_blocks() == 0 || volume.host_blocks_where(needs).empty()) return read();
    }
    std::unique_lock lock(volume_mutex);
    const std::vector<Eigen::Vector3i> back = volume.host_blocks_where(needs);
    const int64_t pool = volume.pool_capacity();
    volume.stream_in(back);
    auto result = read();
    volume.stream_out(back);
    if (who == Reader::Client) volume.shrink_pool(pool);  // the device memory too, as found
    return result;
  }
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
  // mutable: a reader may bring streamed-out blocks back for its read and send them out again
  // (read_view): where the blocks are held changes, never what they hold.
  mutable TsdfVolume volume;
  LockedModelSource model;
  Tracker tracker;
  PlaneIdentifier identifier;
  GaussianMapper mapper;
  std::unique_ptr<MaskSource> masks;  // icp+orb+mask: rendered C_r
  DeviceImage<int32_t> mask_plane_ids;  // I at the ICP pose for the mask (render_reflection)
  Buffer<uint64_t> mask_zbuffer;        // its warp's scratch
  DeviceImage<float> given_normal_depth;  // with given poses: the filtered D_k fusion's normals come from
  DeviceImage<float> frame_depth;         // this frame's D_k as tracked and fused, on the device (reused)
  DeviceImage<Color> frame_color;         // and its colour
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
