#pragma once
// The online Gaussian mapping step (paper §4.2, DESIGN.md §1): every N_o frames the session hands
// the fused frames to the mapper and runs a step (prepare(): 1 and pass 1; run(): the rest):
//   1. frames: N_local = 2 evenly sampled from the frames added since the last step (the newest
//      included) + N_global = 7 random keyframes (seeded: params.seed, step count, newest index);
//   2. densify base and reflection Gaussians on the N_local frames (core/gaussians/densify.h; with
//      densify.reflection_stereo_depth the reflection candidates' depths come from a plane sweep
//      against the step's other frames, core/slam/reflection_stereo.h);
//   3. `iterations` = 30 Adam iterations (a step's MappingContext::iterations when set), each on
//      one of the selected frames (a seeded shuffle of the set, cycled): render C, D_b, C_r →
//      L = (1−λ)L1 + λ(1−SSIM) + λ_d L1(D_b) + λ_g‖Sobel C_r‖₁ → backward → Adam on the visible
//      Gaussians of each set;
//   4. prune both sets (core/gaussians/prune.h), Adam state compacted alongside;
//   5. publish an immutable MapSnapshot for render() / exports.
// Frames: add_frame() takes every fused frame (the session may also pass every N_o-th only); the
// frames since the last step are dropped after it, keyframes are kept for N_global sampling. Host
// copies are compact: 8-bit colour and depth in 1/5000 m steps (uint16, up to 13.1 m).
// The mapper never touches the TSDF: MappingContext::raycast gives pass 1 at any camera.
// Deterministic on the CPU: the same frames, planes and params give the same map.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/gaussians/adam.h"
#include "core/gaussians/densify.h"
#include "core/gaussians/gaussian_grads.h"
#include "core/gaussians/gaussian_set.h"
#include "core/gaussians/losses.h"
#include "core/gaussians/prune.h"
#include "core/gaussians/reflective_plane.h"
#include "core/render/render_types.h"
#include "core/render/renderer.h"
#include "core/slam/optimise_times.h"
#include "core/slam/reflection_stereo.h"
#include "core/tsdf/tsdf_raycast.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <vector>

namespace rrg {

struct ConfigTable;  // core/slam/session_config.h

struct MapperParams {            // paper defaults (DESIGN.md §5); validate() throws invalid_argument
  int iterations = 30;           // per mapping step
  int n_local = 2;               // N_local frames since the last step
  int n_global = 7;              // N_global random keyframes
  float lambda_ssim = 0.2f;      // λ of L_color
  float lambda_depth = 0.2f;     // λ_d
  float lambda_sobel = 0.05f;    // λ_g
  float lambda_reflective_base = 0.3f;  // λ_rb (ours, LossWeights)
  int sh_degree = 3;             // SH degree of new Gaussians (the supplement's lr_SHrest implies > 0)
  uint64_t seed = 0;             // keyframe sampling, frame order, densification sampling
  bool reflections = true;       // false = base only (the --no-reflections ablation)
  DensifyParams densify;         // δ_b, δ_w,b, δ_r, δ_v, δ_w,r, sampling ratio, initialisation
  ReflectionStereoParams reflection_stereo;  // with densify.reflection_stereo_depth (reflection_stereo.h)
  PruneParams prune_base = PruneParams::base();              // 0.005 / 0.003 / 0.1
  PruneParams prune_reflection = PruneParams::reflection();  // 0.005 / 0.005 / 0.2
  AdamParams adam_base{AdamLearningRates::base()};
  AdamParams adam_reflection{AdamLearningRates::reflection()};
  RenderParams render;           // renderer settings (ε = TSDF truncation, ...)
  void validate() const;
  LossWeights loss_weights() const { return {lambda_ssim, lambda_depth, lambda_sobel, lambda_reflective_base}; }
};

// Adds the named fields of MapperParams to a session's configuration table (as "mapping.<name>").
void add_mapper_config_fields(ConfigTable& t, MapperParams& p);

struct MappingFrame {            // one posed RGB-D frame (host)
  int64_t index = 0;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  ColorImage color;              // C_gt
  DepthImage depth;              // D_gt, metres, 0 = invalid
};

// Compact host copy of a mapping frame as the mapper keeps it: 8-bit colour, depth in 1/5000 m.
// from() quantises; color() / depth_m() expand, and from() of the expansion gives the same bytes
// (snapshots store frames in this form, bit for bit).
struct CompactFrame {
  int64_t index = 0;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;      // [H, W, 3]
  std::vector<uint16_t> depth;   // [H, W], 1/5000 m, 0 = invalid
  static CompactFrame from(const MappingFrame& frame);
  ColorImage color() const;
  DepthImage depth_m() const;
  MappingFrame expand() const { return {index, T_wc, color(), depth_m()}; }
};

// What a step depends on besides the two Gaussian sets (session snapshots): the step counter
// (it seeds the frame selection), the stored frames with the keyframe list (N_global sampling)
// and the frames since the last step (N_local), and both sets' Adam state.
struct MapperState {
  uint64_t steps = 0;
  std::vector<CompactFrame> frames;   // each stored frame once
  std::vector<uint32_t> keyframes;    // indices into frames, in insertion order
  std::vector<uint32_t> recent;       // indices into frames, oldest first
  AdamStateHost adam_base, adam_reflection;
};

struct MappingContext {
  // Pass 1 at a camera (the session serialises it against fusion).
  std::function<RaycastResult(const Intrinsics&, const Eigen::Isometry3f&)> raycast;
  std::vector<ReflectivePlane> planes;  // accepted reflective planes (L_ref) with their equations
  // Plane id -> canonical id (GlobalPlaneTable::remap_table(), as the raycasts of this step used):
  // the step first moves reflection Gaussians of a merged-away plane to the id that absorbed it.
  std::vector<int32_t> remap;
  // This step's Adam iterations; 0 = MapperParams::iterations (the live schedule scales them with
  // the frames a step covers, core/slam/mapping_schedule.h).
  int iterations = 0;
};

struct MappingStats {
  int iterations = 0;
  int frames = 0;                  // frames optimised on (local + global)
  int64_t base_added = 0, reflection_added = 0, base_pruned = 0, reflection_pruned = 0;
  int64_t base_size = 0, reflection_size = 0;  // after the step
  double loss = 0;                 // mean total loss over the iterations
  int reflection_skipped = 0;      // iterations whose view shows no reflection Gaussian's plane (pass 3 skipped)
  int planes_relabelled = 0;       // plane ids of reflection Gaussians moved to the canonical id of a merge
  double ms_raycast = 0, ms_densify = 0, ms_optimise = 0, ms_prune = 0, ms_total = 0;
  OptimiseTimes optimise;          // ms_optimise by part
};

struct MapSnapshot {             // immutable for its readers (publish() reuses it once none holds it)
  GaussianSet base, reflection;
  uint64_t version = 0;            // number of published steps / loads
  std::vector<int32_t> reflection_planes;  // the distinct non-zero plane ids l of `reflection`, sorted
};


class GaussianMapper {
 public:
  GaussianMapper(const MapperParams& params, const Intrinsics& K, const Device& device);

  // Queues a fused frame; keyframes are also kept for N_global sampling. Throws
  // std::invalid_argument for a frame whose size differs from K.
  void add_frame(MappingFrame frame, bool keyframe);
  // One mapping step (densify → iterations → prune), then publishes a snapshot. Without any frame
  // (queued or keyframe) it only republishes. Not re-entrant (one step at a time).
  // step() = run(prepare()). prepare() selects the step's frames (consuming the queued ones) and
  // runs pass 1 at each through ctx.raycast; it reads no Gaussian, so the session runs it on the
  // pre-mapping thread while the previous step's run() optimises (live: on the mapping thread,
  // just before run(); docs/slam.md). Prepared steps must be run in the order they were prepared;
  // run() throws std::invalid_argument for a null one.
  struct Prepared;
  std::shared_ptr<Prepared> prepare(const MappingContext& ctx);
  MappingStats run(std::shared_ptr<Prepared> prepared, const MappingContext& ctx);
  MappingStats step(const MappingContext& ctx);
  // The latest published snapshot (never null). Thread-safe.
  std::shared_ptr<const MapSnapshot> snapshot() const;
  // Renders passes 2 and 3 of the latest snapshot at cam over a raycast at the same camera.
  // Thread-safe with step().
  void render(const RenderCamera& cam, const RaycastResult& raycast, RenderOutputs& out) const;
  // C_r alone (pass 3 of the latest snapshot's reflection set over plane-id map I), on the host.
  // Thread-safe with step(). stop_mean: see Renderer::render_reflection (exact where the mean RGB
  // stays <= stop_mean; the tracking mask passes its threshold).
  ColorImage render_reflection(const RenderCamera& cam, const DeviceImage<int32_t>& I,
                               float stop_mean = std::numeric_limits<float>::infinity()) const;
  GaussianHost base_host() const;
  GaussianHost reflection_host() const;
  // Replaces both sets (session load); optimiser state restarts. Publishes a snapshot.
  void load(const GaussianHost& base, const GaussianHost& reflection);
  // The state of a step boundary (waits for a running step), and its restoration after load():
  // throws std::invalid_argument when the Adam state does not match the loaded sets or a frame
  // does not match K (the mapper is unchanged then).
  MapperState export_state() const;
  void import_state(MapperState state);

  const MapperParams& params() const { return params_; }
  const Intrinsics& intrinsics() const { return K_; }
  size_t queued_frames() const;
  size_t keyframes() const;

 private:
  using StoredFrame = CompactFrame;
  struct StepFrame;              // a selected frame with its images on the device for one step
  std::vector<std::shared_ptr<const StoredFrame>> select_frames(uint64_t seed);
  void publish();

  MapperParams params_;
  Intrinsics K_;
  Device device_;
  GaussianSet base_, refl_;
  GaussianSet no_reflection_;    // empty: pass 3 of a view that shows none of refl_'s planes
  GaussianAdam adam_base_, adam_refl_;
  GaussianGrads v_base_, v_refl_, v_no_reflection_;
  Renderer renderer_;
  LossScratch loss_scratch_;
  uint64_t steps_ = 0;           // steps prepared (guarded by frames_mutex_)
  size_t remap_absorbed_ = 0;    // merged-away ids in the remap refl_'s plane ids last went through

  mutable std::mutex frames_mutex_;
  std::deque<std::shared_ptr<const StoredFrame>> recent_;
  std::vector<std::shared_ptr<const StoredFrame>> keyframes_;

  mutable std::mutex step_mutex_;
  mutable std::mutex snapshot_mutex_;
  std::shared_ptr<MapSnapshot> snapshot_;  // handed out as const
  std::shared_ptr<MapSnapshot> spare_;     // the one before: publish() refills it once no reader holds it
  uint64_t version_ = 0;

  mutable std::mutex render_mutex_;
  mutable Renderer query_renderer_;
};

}  // namespace rrg
