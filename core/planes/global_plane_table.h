#pragma once
// The global plane table (supplement, "Global Plane Maintenance"): registers each frame's local
// planes into globally consistent instances.
//  - geometric filter against every live instance: normal angle <= 10°, point-to-plane distance of
//    the local plane's centroid <= 0.1 m;
//  - footprint tests in the candidate's plane basis (grid 0.05 m): cell overlap (1-cell dilation)
//    > 0.05, bounding-box IoU > 0.02, or bounding-box gap < 0.10 m for an instance seen within the
//    last `recent_frames` frames; among matching candidates the highest overlap wins (ours: those
//    whose plane the observation's centroid lies on within LocalPlane::same_plane_distance first);
//    no match creates a new instance;
//  - one frame, one surface per instance (ours): two local planes of one frame that no one plane
//    explains within the segmenter's tolerances (LocalPlane::same_plane_distance, planar_rms) do not
//    share an instance;
//    the larger keeps it, the other takes its next match or a new instance, and the two instances
//    are recorded as seen apart, so the merge pass never joins them (a mirror frame's bar 3.5 cm in
//    front of the mirror, a bookshelf's back 2.5 cm in front of its wall: both within the 0.1 m filter);
//  - union-find merges of instances recognised as one physical plane (the lower id absorbs the
//    higher: moments, plane parameters, footprint and bounding box are unified), and the id remap
//    table (id -> canonical id) used by TSDF fusion and raycasting. Ours: recognised when the smaller
//    footprint lies > 30 % inside the other, or when in two frames a local plane that took one
//    instance also matched the other and was one surface with it (one such frame is the noisy
//    segment the highest-overlap choice keeps from bridging two instances; two are evidence);
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/planes/plane_fit.h"
#include "core/planes/plane_footprint.h"
#include "core/planes/plane_types.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace rrg {

struct PlaneStateIo;

struct GlobalPlaneParams {
  float max_normal_angle_deg = 10.0f;  // geometric filter: normals within 10°
  float max_distance = 0.1f;           // ... and centroid-to-plane distance <= 0.1 m
  float cell_size = 0.05f;             // footprint grid, metres
  float min_overlap = 0.05f;           // match: cell overlap ratio (1-cell dilation) > 0.05
  float min_iou = 0.02f;               //   or bounding-box IoU > 0.02
  float max_gap = 0.10f;               //   or bounding-box gap < 0.10 m for a recent instance
  int recent_frames = 30;              // "recently observed": last seen within 30 frames (3 windows of N_p)
  float merge_min_overlap = 0.3f;      // merge two instances when (geometric filter both ways and) the
                                       // smaller footprint lies this much inside the other, dilated
  int point_stride = 2;                // footprint / moment points: every 2nd pixel in x and y

  void validate() const;               // throws std::invalid_argument naming the bad field
  std::string to_string() const;
};

struct GlobalPlane {
  int id = 0;                          // >= 1, never reused
  Plane plane;                         // world frame
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  PlaneMoments moments;                // of every registered point (world frame)
  Footprint footprint;                 // in the basis fixed at creation
  int64_t first_seen = 0, last_seen = 0;  // frame indices
  int observations = 0;                // frames it was matched in
  float same_plane_distance = 0.01f;   // the smallest LocalPlane::same_plane_distance it was seen with (closest look)
  bool alive = true;                   // false once absorbed by a merge
  std::vector<int> apart;              // instances seen in one frame as a different surface (ids as recorded)
  // (instance, frame): a local plane this instance took in that frame matched that instance too and
  // was one surface with it (ids as recorded). A second such frame merges the two.
  std::vector<std::pair<int, int64_t>> bridged;
};

// One local plane of one frame, in the world frame.
struct LocalObservation {
  int local_id = 0;
  Plane plane;                         // world frame
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  std::vector<Eigen::Vector3f> points; // world frame (subsampled pixels)
  float same_plane_distance = 0.01f;   // LocalPlane::same_plane_distance
  float planar_rms = 0.01f;            // LocalPlane::planar_rms
};

// How one local plane compared with one candidate (for logs and tests).
struct CandidateScore {
  int global_id = 0;
  float overlap = 0, iou = 0, gap = 0;
  bool recent = false, matched = false;
};

struct FrameAssociation {
  std::vector<int> local_to_global;              // [max local id + 1], canonical ids after merges, 0 = none
  std::vector<std::pair<int, int>> merges;       // (kept, absorbed) in merge order
  int created = 0;                               // new instances this frame
};

class GlobalPlaneTable {
 public:
  explicit GlobalPlaneTable(const GlobalPlaneParams& params = {});

  const GlobalPlaneParams& params() const { return params_; }

  // Local planes of a segmentation -> world-frame observations (points every point_stride pixels).
  std::vector<LocalObservation> observe(const PlaneSegmentation& seg, const DepthImage& depth,
                                        const Intrinsics& K, const Eigen::Isometry3f& T_wc) const;
  // Registers one frame's observations (largest first is best), then runs the merge pass.
  FrameAssociation associate(std::span<const LocalObservation> observations, int64_t frame);
  // The footprint tests of one observation against every live instance passing the geometric filter.
  std::vector<CandidateScore> score(const LocalObservation& obs, int64_t frame) const;

  // Union-find merge (lower id absorbs higher); returns false when already one instance.
  bool merge(int a, int b);
  // Whether instances a and b were seen in one frame as different surfaces (the merge pass skips them).
  bool seen_apart(int a, int b) const;
  int canonical(int id) const;                   // find(); ids out of range map to themselves
  std::vector<int32_t> remap_table() const;      // [next id], id -> canonical id, [0] = 0
  // Local plane map -> global plane map I_k^g (canonical ids, 0 = none).
  Image<int32_t> global_map(const LabelImage& local_labels, const FrameAssociation& assoc) const;

  const GlobalPlane* find(int id) const;         // the canonical instance of id; nullptr if unknown
  std::vector<int> live_ids() const;
  size_t size() const { return planes_.size(); }  // instances ever created

 private:
  friend struct PlaneStateIo;  // snapshots (plane_state_io.h)
  float cos_max_normal_angle() const;  // cos of the geometric filter's normal angle
  bool geometric_match(const Plane& a, const Eigen::Vector3f& centroid_b) const;
  // `moments`: of obs.points, computed once per frame by associate().
  void absorb(GlobalPlane& into, const LocalObservation& obs, const PlaneMoments& moments, int64_t frame);
  int create(const LocalObservation& obs, const PlaneMoments& moments, int64_t frame);
  void merge_pass(std::span<const int> touched, FrameAssociation& out);

  GlobalPlaneParams params_;
  std::vector<GlobalPlane> planes_;              // planes_[id - 1]
  mutable std::vector<int> parent_;              // union-find over ids; parent_[0] = 0
};

}  // namespace rrg
