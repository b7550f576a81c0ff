#pragma once
// Recovery when ICP diverges: ORB relocalisation against the keyframes. The frame's keypoints with
// depth are matched brute force to each recent keyframe; a 3-point rigid RANSAC (3D-3D, Umeyama)
// finds the pose with the most points within inlier_distance, refitted on its inliers and then
// refined by motion-only BA. Deterministic (fixed seed).
#include "core/tracking/keyframes.h"
#include "core/tracking/orb_features.h"
#include "core/tracking/tracking_params.h"

#include <Eigen/Geometry>

namespace rrg {

struct RelocResult {
  bool ok = false;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  int inliers = 0;        // BA inliers of the best keyframe
  int keyframe_id = -1;   // the keyframe it relocalised against
};

RelocResult relocalise(const OrbFrame& frame, const KeyframeSet& keyframes, const Intrinsics& K,
                       const TrackingParams& params);

}  // namespace rrg
