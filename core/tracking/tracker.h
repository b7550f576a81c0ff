#pragma once
// Reflection-aware tracking of one RGB-D stream (paper §4.1.2): per frame
//   1. preprocessing (bilateral filter, 3-level pyramid, V_k^l and N_k^l),
//   2. ICP against the model raycast at T_{k−1}, initialised by the constant-velocity prior,
//   3. (icp+orb[+mask]) ORB on the pixels where R_k^track = 0 (mask rendered at the ICP pose),
//      matched to the map points of a local window of keyframes, motion-only BA from the ICP pose;
//      too few inliers (or an implausible correction) keep the ICP pose and say so,
//   4. a tracking state: ok, degraded (weak ICP, or recovered this frame) or lost (ICP failed and
//      ORB relocalisation against the keyframes failed too; the frame should not be fused),
//   5. keyframe insertion on δ_angle / δ_move.
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/tracking/icp.h"
#include "core/tracking/keyframes.h"
#include "core/tracking/mask_source.h"
#include "core/tracking/model_source.h"
#include "core/tracking/preprocess.h"
#include "core/tracking/tracking_params.h"

#include <Eigen/Geometry>

#include <string>

namespace rrg {

enum class TrackingState { Ok, Degraded, Lost };
std::string to_string(TrackingState state);

struct TrackInput {
  size_t index = 0;                                // frame number (mask lookup, keyframe ids)
  const ColorImage* color = nullptr;               // C_k, host, registered to the depth
  const DepthImage* depth = nullptr;               // D_k, host, metres
  const DeviceImage<float>* depth_device = nullptr;  // D_k on the tracker's device (uploaded when null)
};

struct TrackResult {
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();  // T_g,k (last good pose when lost)
  TrackingState state = TrackingState::Ok;
  bool first = false;           // the first frame: pose given, nothing tracked
  IcpResult icp;                // stage 1
  bool orb_refined = false;     // stage 2 changed the pose
  int orb_keypoints = 0, orb_matches = 0, orb_inliers = 0;
  int64_t mask_pixels = 0;      // R_k^track's pixels (icp+orb+mask), kept out of ORB
  bool relocalised = false;
  bool keyframe = false;        // a keyframe was inserted
  std::string note;             // why stage 2 was skipped / rejected, relocalisation, ...
  double ms_preprocess = 0, ms_icp = 0, ms_orb = 0;
  double ms_mask = 0;  // of ms_orb: the tracking mask (icp+orb+mask)
};

// Everything track() carries from one frame to the next (session snapshots: a restored tracker
// continues exactly as the uninterrupted one; serialised by core/tracking/tracker_state_io.h).
struct TrackerState {
  bool started = false;
  Eigen::Isometry3f T_initial = Eigen::Isometry3f::Identity();
  Eigen::Isometry3f T_prev = Eigen::Isometry3f::Identity();    // T_{k−1}
  Eigen::Isometry3f velocity = Eigen::Isometry3f::Identity();  // T_{k−2}⁻¹ T_{k−1}
  TrackingState state = TrackingState::Ok;
  int next_keyframe_id = 0;
  std::vector<Keyframe> keyframes;  // oldest first
};

class Tracker {
 public:
  // Throws std::invalid_argument for bad params or intrinsics.
  Tracker(const TrackingParams& params, const Intrinsics& K, const Device& device);

  // Pose of the first frame (identity unless set); call before the first track().
  void set_initial_pose(const Eigen::Isometry3f& T_wc);
  // Replaces the motion prior: the next frame is predicted at T_wc with zero velocity (an external
  // pose prior, or a kidnapped camera in tests).
  void set_pose_prior(const Eigen::Isometry3f& T_wc);
  // Continues a stream that stopped at T_wc (a restored session snapshot): the next frame is tracked
  // against the model, predicted at T_wc with zero velocity; no keyframes are kept.
  void resume(const Eigen::Isometry3f& T_wc);
  // The carried state, and its restoration (keyframes beyond params.keyframes.max_keyframes drop
  // the oldest, as add() does). The last frame's pyramid is not part of it: track() rebuilds it.
  TrackerState export_state() const;
  void import_state(const TrackerState& state);

  // Tracks one frame. `model` serves the map raycast (not used on the first frame); `masks` gives
  // R_k^track in icp+orb+mask mode (required there). Throws std::invalid_argument on size mismatch.
  TrackResult track(const TrackInput& input, ModelSource& model, MaskSource* masks);

  // The bilateral-filtered D_k of the last frame given to track() (its depth when the filter is
  // off), on the tracker's device: the depth fusion should take its normals from, while it fuses
  // the sensor's depth (integrate(..., normal_depth)). At fine resolutions (640x480) Kinect-like
  // noise (σ ≈ 2 cm at 3.5 m) exceeds the pixel spacing (7 mm), so normals from central
  // differences of the raw depth are noise; the TSDF's point-to-plane sdf and its grazing-angle
  // test then drop half the surface and ICP loses track. Fusing the filtered depth itself instead
  // biases the map by view (docs/tracking.md). Null before the first frame.
  const DeviceImage<float>* normal_depth() const {
    return pyramid_.levels.empty() ? nullptr : &pyramid_.levels[0].normal_depth();
  }
  TrackingState state() const { return state_; }
  const KeyframeSet& keyframes() const { return keyframes_; }
  const TrackingParams& params() const { return params_; }
  // Constant-velocity prediction T_{k−1} (T_{k−2}⁻¹ T_{k−1}) of the next pose.
  Eigen::Isometry3f predicted_pose() const { return T_prev_ * velocity_; }

 private:
  bool icp_failed(const IcpResult& icp) const;
  void add_keyframe(size_t index, const Eigen::Isometry3f& T_wc, const OrbFrame& orb);

  TrackingParams params_;
  Intrinsics K_;
  Device device_;
  bool started_ = false;
  Eigen::Isometry3f T_initial_ = Eigen::Isometry3f::Identity();
  Eigen::Isometry3f T_prev_ = Eigen::Isometry3f::Identity();
  Eigen::Isometry3f velocity_ = Eigen::Isometry3f::Identity();  // T_{k−2}⁻¹ T_{k−1}
  TrackingState state_ = TrackingState::Ok;
  KeyframeSet keyframes_;
  FramePyramid pyramid_;  // of the last frame, rebuilt in place by each track()
  DeviceImage<float> upload_;  // the frame's depth on the device when the caller gives it on the host only
  int next_keyframe_id_ = 0;
};

}  // namespace rrg
