#pragma once
// Tracking keyframes: the ORB map points of stage 2 and of relocalisation. A keyframe keeps the
// keypoints that had a valid depth, their descriptors and their world points X = T_wc p_c.
// Insertion by the paper's motion heuristic: rotation to the last keyframe > δ_angle or
// translation > δ_move (tracking_params.h documents the tracking defaults).
#include "core/tracking/orb_features.h"
#include "core/tracking/tracking_params.h"

#include <Eigen/Geometry>

#include <deque>
#include <vector>

namespace rrg {

struct Keyframe {
  int id = 0;
  size_t frame_index = 0;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  std::vector<cv::KeyPoint> keypoints;       // only those with depth
  cv::Mat descriptors;                       // [N, 32]
  std::vector<Eigen::Vector3f> points_world; // [N] X_j, world frame
};

// True when the motion from the last keyframe exceeds δ_angle (degrees) or δ_move (metres).
bool needs_keyframe(const Eigen::Isometry3f& T_wc_last_keyframe, const Eigen::Isometry3f& T_wc,
                    const KeyframeParams& params);

// Keyframe of a posed ORB frame (keypoints without depth dropped).
Keyframe make_keyframe(int id, size_t frame_index, const Eigen::Isometry3f& T_wc, const OrbFrame& orb);

class KeyframeSet {
 public:
  explicit KeyframeSet(int max_keyframes) : max_(max_keyframes) {}
  void add(Keyframe keyframe);               // drops the oldest beyond max_keyframes
  bool empty() const { return frames_.empty(); }
  size_t size() const { return frames_.size(); }
  const Keyframe& back() const { return frames_.back(); }
  // The `count` most recent keyframes, newest first.
  std::vector<const Keyframe*> recent(int count) const;
  const std::deque<Keyframe>& all() const { return frames_; }  // oldest first
  void clear() { frames_.clear(); }

 private:
  int max_;
  std::deque<Keyframe> frames_;
};

}  // namespace rrg
