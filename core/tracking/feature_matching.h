#pragma once
// Matching ORB keypoints of the current frame to keyframe map points (stage 2 of tracking and
// relocalisation): guided search around projected map points with Lowe's ratio test and
// ORB-SLAM's rotation-consistency histogram, and unguided brute-force matching for relocalisation.
#include "core/tracking/keyframes.h"
#include "core/tracking/orb_features.h"

#include <Eigen/Geometry>

#include <vector>

namespace rrg {

struct FeatureMatch {
  int keypoint = 0;                 // index into the current OrbFrame
  Eigen::Vector3f X_w;              // matched map point
  int distance = 0;                 // Hamming
};

// Map points of `window` projected with T_wc into the current frame (camera K); each is matched to
// the keypoints within params.search_radius_px (scaled by the keypoint's octave) whose descriptor
// is closest, kept when best <= max_hamming and best < ratio · second best. Matches are then
// filtered by rotation consistency (keypoint angle differences, the 3 fullest of
// params.rotation_bins bins) and each keypoint keeps its closest map point.
std::vector<FeatureMatch> match_by_projection(const OrbFrame& frame, const std::vector<const Keyframe*>& window,
                                              const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                                              const OrbParams& params);

// Brute-force matches of the frame's keypoints that have depth to one keyframe's points (ratio
// test, Hamming limit, rotation consistency); no pose needed.
std::vector<FeatureMatch> match_brute_force(const OrbFrame& frame, const Keyframe& keyframe, const OrbParams& params);

// Keeps the matches whose angle difference falls into the `bins`-bin histogram's 3 fullest bins
// (ORB-SLAM2 ComputeThreeMaxima; a bin under 10 % of the fullest is dropped). angle_diff in degrees.
std::vector<int> rotation_consistent(const std::vector<float>& angle_diff_deg, int bins);

}  // namespace rrg

#include "core/tracking/motion_ba.h"

namespace rrg {

// BA observations of matches: (u, v) of the keypoint, u_R = u − b f_x / z when it has depth, and
// Ω = scale_factor^(−2·octave).
std::vector<BaObservation> to_observations(const OrbFrame& frame, const std::vector<FeatureMatch>& matches,
                                           const OrbParams& params);

}  // namespace rrg
