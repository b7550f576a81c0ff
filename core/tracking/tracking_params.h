#pragma once
// Parameters of reflection-aware tracking (paper §4.1.1-4.1.2, DESIGN.md §5) with their defaults,
// and the ablation switch of the paper's tracking ablation (icp | icp+orb | icp+orb+mask).
#include "core/common/depth_noise_model.h"

#include <string>

namespace rrg {

// Which stages run: ICP only ("w/o ORB refinement"), ICP + ORB on every pixel ("w/o tracking
// mask"), or ICP + ORB on the pixels where the tracking mask R_k^track is 0 (the full model).
enum class TrackingMode { Icp, IcpOrb, IcpOrbMask };
TrackingMode parse_tracking_mode(const std::string& text);  // "icp" | "icp+orb" | "icp+orb+mask"
std::string to_string(TrackingMode mode);

struct PreprocessParams {
  bool bilateral = true;          // bilateral filter on D_k before the vertex/normal maps
  int bilateral_radius = 3;       // 7x7 window (KinectFusion)
  float sigma_space_px = 4.5f;    // σ_s, pixels at level 0
  float sigma_depth_m = 0.03f;    // σ_d, metres
  int levels = 3;                 // pyramid levels, level l is (w / 2^l) x (h / 2^l)
};

struct IcpParams {
  int iterations[3] = {10, 5, 4}; // Gauss-Newton steps per level (0 = finest), coarse to fine
  float max_distance_m = 0.10f;   // reject pairs farther apart (after the current estimate)
  float max_normal_angle_deg = 30.0f;  // reject pairs whose normals differ more
  float huber_delta_m = 0.01f;    // robust weight w = min(1, δ / |r|) on the point-to-plane residual
                                  // (with noise weighting: on r scaled to the reference depth's noise)
  // Noise weighting (Nguyen, Izadi & Lovell 2012): each pair's residual is divided by the sensor's
  // axial noise σ_n(z) at the source point's depth, so a pair 4 m away (σ_n 2.6 cm on a Kinect v1)
  // counts as the 1/180 of a pair at 1 m (1.9 mm) that its variance says, instead of the same. The
  // weight is (σ_n(z_ref) / σ_n(z))² and Huber applies to r σ_n(z_ref) / σ_n(z): at the reference
  // depth both are as without weighting. The model is the sensor's (SessionConfig keeps it equal to
  // planes.segmentation's).
  bool noise_weighting = true;
  float noise_reference_depth_m = 1.0f;
  // σ_m, metres: the model surface's own error, added in quadrature to σ_n(z) in the weights,
  // σ² = σ_n(z)² + σ_m² (0: the sensor's noise alone). Measured, not adopted: docs/tracking.md
  // "A model term beside σ_n(z)".
  float model_sigma_m = 0.0f;
  DepthNoiseModel noise;
  // The tracking state's quality measure, IcpResult::agreement: the share of the frame's valid
  // pixels whose pair agrees with the model, |p − q| <= max_distance and a point-to-plane residual
  // the sensor's noise explains, |r| <= max(huber_delta, agreement_sigmas σ_n(z)). The normal-angle
  // rejection is left out of it: normals from depth 3–4 m away (σ_n 2–3 cm over a 1.4 cm pixel
  // footprint) differ by more than 30° on most pairs of a correct pose, and a room seen from its
  // far side would read as lost (docs/tracking.md "Agreement, not inliers").
  float agreement_sigmas = 3.0f;
  float min_agreement = 0.25f;    // below: ICP failed (diverged or no overlap)
  float ok_agreement = 0.50f;     // below (and above min): tracking degraded
  float max_jump_m = 0.30f;       // an ICP step farther than this from the motion prior diverged
  float max_jump_deg = 30.0f;
  // Stop a level when the update moves the scene by less than ~0.1 mm: |ρ| < 0.1 mm and |φ| < 1e-4
  // rad (0.1 mm at 1 m). That is below the depth quantisation of 16-bit depth (0.2 mm at 1/5000 m)
  // and 10x below the 1 mm / 0.1° accuracy asked of ICP, so further steps only chase noise.
  float converge_translation_m = 1e-4f;
  float converge_rotation_rad = 1e-4f;
};

struct OrbParams {
  int features = 1000;            // ORB features per frame (OpenCV ORB, 8 levels, factor 1.2)
  int levels = 8;
  float scale_factor = 1.2f;
  float min_depth_m = 0.1f, max_depth_m = 6.0f;  // keypoints need a valid depth to become map points
  // A keypoint on a depth discontinuity (an occlusion corner, a silhouette) is no fixed 3D point: the
  // corner moves along the background as the camera moves, and the depth at its rounded pixel may
  // be either side. When the valid depths in its window (half-width max(1, round(1.2^octave)) px)
  // span more than this fraction of its own depth, it keeps no depth: no map point, a monocular
  // observation. 5 % is above Kinect v1's noise over a window (±2σ_n ≈ 2 % of z at 3 m) plus an 80°
  // oblique plane across 2 px at f = 256 (docs/tracking.md "Keypoints on depth edges"). 0 = off.
  float max_depth_range = 0.05f;
  float ratio = 0.8f;             // Lowe ratio test (best / second best Hamming distance)
  int max_hamming = 64;           // descriptor distance limit (ORB-SLAM2 TH_HIGH = 100, TH_LOW = 50)
  float search_radius_px = 12.0f; // guided matching: keypoint within this of the projected map point
  int rotation_bins = 30;         // rotation consistency histogram (keep the 3 fullest bins)
  int window_keyframes = 5;       // local window of keyframes whose points are matched
  int min_inliers = 20;           // fewer after BA: keep the ICP pose and say so
  float max_correction_m = 0.05f; // a BA result farther than this from the ICP pose is rejected
  float max_correction_deg = 3.0f;
  float mask_threshold = 0.1f;    // R_k^track = mean RGB of C_r > 0.1
  // A session also keeps out the planes whose reflection is not modelled yet: semantic candidates
  // with an open vote, accepted planes without reflection Gaussians (docs/tracking.md "Reflections
  // not modelled yet"). false: the paper's C_r test alone.
  bool mask_unmodelled = true;
  // A session can render R_k^track at 1/mask_downsample of the frame's width and height, each of
  // its pixels then covering f × f frame pixels, at 1/f² of the raycast and render; ORB dilates the
  // mask by 7 px (orb_features.cpp). 1 (default) = full resolution, as the paper (docs/tracking.md).
  int mask_downsample = 1;
  // A session takes the mask's plane-id map I from the ICP model's raycast at T_{k−1}, warped to
  // the ICP pose (core/tsdf/raycast_warp.h), instead of raycasting the TSDF again there: one
  // frame's motion moves a plane's edge by about a pixel against ORB's 7 px dilation of the mask
  // (docs/tracking.md). false: the raycast at the ICP pose.
  bool mask_warp = true;
  // s of the ICP prior Λ = s JᵀJ_icp / σ_icp² in the BA (0 = none). JᵀJ / σ² counts every pixel
  // pair as an independent measurement, but neighbouring residuals share the model's error: against
  // ground truth ICP knows less than it claims (mean NEES / 6 = 4–31 on the three presets since its
  // positions are the sensor's; 53–185 before), while the BA's own Σ Ω JᵀJ is within 1.3–2.8x of
  // what the features know. s = 0.1 is ICP's honest information next to the BA's, 1/k_icp between
  // mirror_room's 0.03 and office's 0.26 (bench/consistency, docs/tracking.md "How much to trust ICP").
  float icp_prior_scale = 0.1f;
  // Consistency gate: the BA correction Δ = log(T_ba T_icp⁻¹) must satisfy Δᵀ Λ Δ <= χ²₆(99 %)
  // = 16.81 with the same ICP information Λ = s JᵀJ_icp / σ_icp² as the prior (off when s = 0):
  // ORB may move the pose along directions the geometry leaves weak, not against what it fixes.
  float icp_consistency_chi2 = 16.81f;
  float baseline_fx = 40.0f;      // b·f_x (pixels·m) of the virtual stereo residual (ORB-SLAM2 RGB-D)
};

struct BaParams {
  int rounds = 4;                 // ORB-SLAM2 PoseOptimization: 4 rounds of 10 iterations,
  int iterations = 10;            // outliers re-classified after each round
  double chi2_mono = 5.991;       // χ²(2 dof, 95 %)
  double chi2_stereo = 7.815;     // χ²(3 dof, 95 %)
};

struct KeyframeParams {
  // ORB map points need views close to the current one, so tracking keyframes are denser than
  // GPS-SLAM's optimisation keyframes (30°, 0.3 m; DESIGN.md §5): δ_angle = 10°, δ_move = 0.1 m.
  float delta_angle_deg = 10.0f;
  float delta_move_m = 0.10f;
  int max_keyframes = 200;        // oldest dropped beyond (relocalisation searches all kept ones)
};

struct RelocParams {
  int ransac_iterations = 200;    // 3-point rigid (3D-3D) hypotheses
  float inlier_distance_m = 0.05f;
  int min_inliers = 25;
  int max_keyframes = 20;         // most recent keyframes tried
};

struct TrackingParams {
  TrackingMode mode = TrackingMode::IcpOrbMask;
  PreprocessParams preprocess;
  IcpParams icp;
  OrbParams orb;
  BaParams ba;
  KeyframeParams keyframes;
  RelocParams reloc;

  // Throws std::invalid_argument naming the first bad field.
  void validate() const;
};

}  // namespace rrg
