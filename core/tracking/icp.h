#pragma once
// Stage 1 of reflection-aware tracking (paper §4.1.2): frame-to-model point-to-plane ICP
//   E(ξ) = Σ_u ‖(T_g,k V_k^l(u) − V*_{k−1}^g(û)) · N*_{k−1}^g(û)‖,  û = proj(K T_{k−1}⁻¹ T_g,k V_k^l(u))
// with projective association, distance / normal-angle rejection, Huber weights and Gauss-Newton
// on SE(3), coarse to fine over the frame pyramid. The per-pixel normal equations are reduced by
// the device layer on the device the maps live on. The model (any raycast: world-frame vertices
// and normals and the camera they were cast from) is a plain input, so ICP needs no TSDF.
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/tracking/icp_device.h"
#include "core/tracking/preprocess.h"
#include "core/tracking/tracking_params.h"

#include <Eigen/Geometry>

namespace rrg {

struct IcpModel {
  const DeviceImage<Eigen::Vector3f>* vertices = nullptr;  // V*_{k−1}^g, world frame, 0 = none
  const DeviceImage<Eigen::Vector3f>* normals = nullptr;   // N*_{k−1}^g, world frame, unit
  Intrinsics K;                                            // camera of the raycast
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();  // its pose T_{k−1}
};

struct IcpResult {
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();  // T_g,k^icp
  int iterations = 0;          // Gauss-Newton steps taken, all levels
  bool converged = false;      // the last step at level 0 was below the convergence thresholds
  bool diverged = false;       // the result jumped too far from the initial pose
  int64_t inliers = 0;         // level 0 pairs that passed rejection at the final pose
  int64_t valid = 0;           // level 0 pixels with a vertex and a normal
  float inlier_ratio = 0.0f;   // inliers / valid
  int64_t agreeing = 0;        // level 0 pairs within max_distance whose |r| <= max(δ, k σ_n(z)), any normal
  float agreement = 0.0f;      // agreeing / valid: the quality measure of the state machine
  float rmse_m = 0.0f;         // RMS point-to-plane residual of the inliers
  float rmse_ref_m = 0.0f;     // the same of the residuals scaled to the reference noise (= rmse_m
                               // without noise weighting): the σ that goes with jtj
  float condition = 0.0f;      // λ_min / λ_max of JᵀJ at level 0 (small: degenerate geometry)
  Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();  // Σ w JᵀJ at level 0, final pose
};

// The reduced 6x6 system at one pose (one Gauss-Newton step's worth), on the source's device.
// Throws std::invalid_argument when the model is missing or on another device than the source.
kernel::IcpSystem reduce_icp_system(const VertexNormalMaps& source, const IcpModel& model,
                                    const Eigen::Isometry3f& T_wc, const IcpParams& params);

// Solves JᵀJ ξ = −Jᵀr (LDLT). Returns false when the system is rank deficient or too few pairs.
bool solve_icp_step(const kernel::IcpSystem& system, Eigen::Matrix<double, 6, 1>& xi);

// Full ICP from T_wc_init (the constant-velocity prediction), coarse to fine.
IcpResult icp_align(const FramePyramid& frame, const IcpModel& model, const Eigen::Isometry3f& T_wc_init,
                    const IcpParams& params);

}  // namespace rrg
