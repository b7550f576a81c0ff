#pragma once
// One online reconstruction session (paper §4, DESIGN.md §1): the hybrid map (augmented TSDF, base
// and reflection Gaussians, global plane table, keyframes) and the paper's schedule:
//   every frame        pre-mapping on the caller's thread: preprocess -> track (ICP -> masked ORB)
//                      -> fuse the TSDF;
//   every N_p frames   plane identification (segmentation -> global table -> semantic cue ->
//                      variance check -> 5-window vote) and fusion of the reflection attributes;
//   every N_o frames   a Gaussian mapping step (densify -> 30 iterations -> prune) on the mapping
//                      thread, overlapping the next frames' pre-mapping (SessionConfig::sync = false),
//                      or inline at the same frame positions (sync = true: deterministic); with
//                      live = true pre-mapping never waits for a running step (mapping_schedule.h).
// process() is called by one thread (the session's worker); every const query below may be called
// from any thread at the same time (renders use the last published Gaussian snapshot and take the
// volume lock only for the raycast). With tsdf.stream_radius > 0 the TSDF blocks far from the
// camera live in host memory between frames; every query still sees the whole map (the blocks it
// needs come back for it and go out again; docs/tsdf.md "Streaming in a session").
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/common/mesh.h"
#include "core/gaussians/gaussian_set.h"
#include "core/gaussians/reflective_plane.h"
#include "core/io/trajectory.h"
#include "core/slam/optimise_times.h"
#include "core/slam/session_config.h"
#include "core/tracking/tracker.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rrg {

class SemanticCue;

// One RGB-D frame as the session takes it (host images of the session's size, registered).
struct SessionFrame {
  int64_t index = 0;                         // strictly increasing within a session
  double timestamp = 0;                      // seconds
  ColorImage color;                          // C_k, RGB in [0, 1]
  DepthImage depth;                          // D_k, metres, 0 = invalid
  std::optional<LabelImage> labels;          // per-pixel semantic categories (the labels cue)
  std::optional<Eigen::Isometry3f> pose;     // a pose prior, or the pose itself with config.gt_poses
};

// Milliseconds of one frame's stages (0 where a stage did not run).
struct StageTimes {
  double decode = 0;       // filled by callers that decode (the service)
  double raycast = 0;      // model raycast at T_{k-1} for ICP
  double preprocess = 0;
  double icp = 0;
  double orb = 0;          // ORB + motion-only BA (+ the tracking mask)
  double mask = 0;         // of orb: the tracking mask R_k^track (its plane-id map and pass 3)
  double fuse = 0;
  double stream = 0;       // of fuse: streaming out the blocks far from the camera (tsdf.stream_radius)
  double identify = 0;     // plane identification incl. its C_var raycast, the cue's masks and the
                           // reflective depth fill (planes.fill; on frames that do not identify too)
  double mapping = 0;      // a mapping step run inline (sync) or waited for
  double total = 0;        // the whole process() call
};

struct FrameReport {
  int64_t index = 0;
  double timestamp = 0;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  TrackingState state = TrackingState::Ok;
  bool fused = false;              // false when lost (the frame is not fused)
  bool identified = false;         // plane identification ran on this frame
  float exposure_gain = 1.0f;      // its exposure against the map, fused into C_var (1: none estimated)
  int64_t filled_pixels = 0;       // depth pixels filled on reflective masks (planes.fill)
  int64_t tracking_mask_pixels = 0; // R_k^track's pixels kept out of ORB (icp+orb+mask)
  bool mapping_started = false;    // a mapping step was started (async) or run (sync) after it
  uint64_t map_version = 0;        // after this frame
  std::string note;                // tracking note
  StageTimes times;
};

// The images of one render (host, the camera's size).
struct SessionView {
  ColorImage C;      // final colour C = C_b + R C_r
  ColorImage C_b;    // base (TSDF + base Gaussians)
  ColorImage C_r;    // reflection Gaussians' colour
  ColorImage RC_r;   // R * C_r
  MaskImage R;       // reflection mask (0 / 1)
  DepthImage depth;  // D_b, metres
};

// Statistics of one mapping step, and their sums over a session.
struct MappingSummary {
  int64_t steps = 0;
  int64_t iterations = 0;          // Adam iterations, summed over steps (live: scaled per step)
  int64_t waits = 0;               // steps that waited for the one before to end (never with live)
  int64_t thinned = 0;             // live: queued frames dropped before reaching a step (thin_live_queue)
  int64_t queued = 0;              // fused frames waiting for the next step (after the last processed frame)
  int64_t base_gaussians = 0, reflection_gaussians = 0;
  double ms_total = 0;             // summed over steps
  // Its stages, summed over steps (MappingStats): the keyframes' TSDF raycasts, densification,
  // the Adam iterations, pruning.
  double ms_raycast = 0, ms_densify = 0, ms_optimise = 0, ms_prune = 0;
  OptimiseTimes optimise;          // ms_optimise by part, summed over steps
  double last_loss = 0;
};

struct SessionStatus {
  int64_t frames = 0;              // processed
  int64_t fused = 0;               // fused into the map
  int64_t lost = 0;
  int64_t last_index = -1;
  TrackingState state = TrackingState::Ok;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();  // last pose
  uint64_t map_version = 0;        // bumps on every fusion and mapping step
  int64_t tsdf_blocks = 0;         // resident and streamed out (tsdf.stream_radius)
  int64_t resident_blocks = 0;     // of which on the volume's device
  int64_t keyframes = 0;
  int64_t global_planes = 0;
  std::vector<int> reflective_planes;  // accepted (L_ref), canonical ids
  MappingSummary mapping;
  size_t device_bytes = 0, host_bytes = 0;
  size_t tsdf_device_bytes = 0;    // of device_bytes: the TSDF's (the rest estimates the Gaussians')
};

class Session {
 public:
  // Throws std::invalid_argument for a bad config (naming the field). `cue` overrides the cue the
  // config names (tests, in-process segmenters).
  explicit Session(SessionConfig config, std::unique_ptr<SemanticCue> cue = nullptr);
  ~Session();  // stops the mapping thread (an unfinished step is completed first)
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const SessionConfig& config() const;

  // Pre-mapping of one frame, on the calling thread; schedules identification and mapping.
  // Throws std::invalid_argument for a frame of the wrong size or an index not above the last
  // one; the session is unchanged then.
  FrameReport process(const SessionFrame& frame);
  // Waits for a running mapping step (async mode). process() and queries stay usable.
  void flush();
  // End of a sequence: flush, then run config.final_steps further mapping steps over the keyframes.
  void finish();

  // Thread-safe queries.
  SessionView render(const Intrinsics& K, const Eigen::Isometry3f& T_wc) const;
  TriangleMesh mesh(uint64_t changed_since = 0) const;   // marching cubes (of blocks changed since)
  // Chunked mesh streaming (the HTTP viewer): the TSDF blocks (resident or streamed out) fused into
  // after volume version `since` (0 = all) with the volume version they are current to, read under
  // one lock; and marching cubes of just the given blocks (welded among themselves).
  struct ChangedBlocks {
    std::vector<Eigen::Vector3i> blocks;
    uint64_t volume_version = 0;
  };
  ChangedBlocks changed_blocks(uint64_t since) const;
  TriangleMesh mesh_of_blocks(const std::vector<Eigen::Vector3i>& blocks) const;
  GaussianHost base_gaussians() const;
  GaussianHost reflection_gaussians() const;
  std::vector<ReflectivePlane> reflective_planes() const;  // accepted planes with equations
  io::Trajectory trajectory() const;                     // one pose per processed frame
  std::vector<FrameReport> reports() const;              // one per processed frame
  SessionStatus status() const;

  // Snapshots: versioned, checksummed, written atomically (a failed save leaves the old file).
  // load() rebuilds a session that continues where the saved one stopped: exactly as the saved
  // session would have (format v2: keyframes, motion and optimiser state are saved; docs/slam.md).
  void save(const std::filesystem::path& file) const;
  static std::unique_ptr<Session> load(const std::filesystem::path& file,
                                       std::unique_ptr<SemanticCue> cue = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rrg
