#pragma once
// Motion-only bundle adjustment (paper §4.1.2 stage 2, ORB-SLAM2's PoseOptimization): the camera
// pose that minimises the robust reprojection error of fixed map points,
//   min_T Σ_i ρ_Huber( e_iᵀ Ω_i e_i ),  e_i = z_i − π(T_cw X_i),  Ω_i = σ_i⁻² I,
// with z = (u, v) or, when the keypoint has depth, the RGB-D "virtual stereo" (u, v, u_R),
// u_R = u − b f_x / z. Gauss-Newton on SE(3); a few rounds, after each of which every observation
// is re-classified by a χ² test (5.991 for 2 dof, 7.815 for 3 dof); the last round has no Huber.
#include "core/common/camera.h"
#include "core/tracking/tracking_params.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <span>
#include <vector>

namespace rrg {

struct BaObservation {
  Eigen::Vector3d X_w = Eigen::Vector3d::Zero();  // map point, world frame (fixed)
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();   // keypoint, pixels
  double u_right = -1.0;                          // virtual right-image u_R; < 0: monocular
  double inv_sigma2 = 1.0;                        // Ω = σ⁻², σ = scale factor ^ octave
};

struct BaResult {
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  int inliers = 0;               // observations passing the χ² test at the final pose
  std::vector<uint8_t> inlier;   // per observation
  double rms_px = 0.0;           // RMS reprojection error of the inliers (u, v only)
  // Σ Ω_i J_iᵀ J_i of the inliers at the final pose (no Huber weight) in the PosePrior's coordinates
  // (e = [ρ; φ] of T_wc T⁻¹): the information the features claim about the pose, e.g. to check it
  // against ground truth (bench/consistency).
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();
};

// A Gaussian prior on the pose: e = [ρ; φ] of T_wc T_prior⁻¹ (left, world-frame twist, as ICP's
// Jacobian), cost eᵀ Λ e. Stage 2 uses the ICP pose with Λ = s · JᵀJ_icp / σ_icp², so the features
// correct what the geometry leaves weak instead of overriding what it constrains well.
struct PosePrior {
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();  // Λ
};

// Starts from T_wc_init (the ICP pose). bf is b·f_x of the virtual stereo residual. With a prior,
// its term is added to every Gauss-Newton step.
BaResult optimize_pose(std::span<const BaObservation> observations, const Intrinsics& K, double bf,
                       const Eigen::Isometry3d& T_wc_init, const BaParams& params, const PosePrior* prior = nullptr);

// Evidence for accepting a refinement: at a pose, the observations passing the χ² test and the
// MSAC cost Σ_i min(χ²_i, χ²_th) (an outlier costs its threshold). Stage 2 keeps the BA pose only
// when it beats the ICP pose on both: more or as many inliers and a lower cost.
struct PoseScore {
  int inliers = 0;
  double cost = 0.0;
};
PoseScore score_pose(std::span<const BaObservation> observations, const Intrinsics& K, double bf,
                     const Eigen::Isometry3d& T_wc, const BaParams& params);

}  // namespace rrg
