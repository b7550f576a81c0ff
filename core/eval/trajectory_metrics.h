#pragma once
// Trajectory accuracy as TUM RGB-D's evaluate_ate.py / evaluate_rpe.py (Sturm et al. 2012).
//   ATE: poses associated by timestamp, estimated positions aligned to the reference by the
//        closed-form rigid fit (Sim(3) only when asked), RMSE of ‖q_i − (s·R·p_i + t)‖ in cm.
//   RPE: for each i, the j whose time t_j is closest to t_i + Δ;
//        E_ij = (Q_i⁻¹ Q_j)⁻¹ (P_i⁻¹ P_j), P estimated, Q reference; RMSE of ‖trans(E)‖ (cm per Δ)
//        and of angle(E) (deg per Δ). Relative, so no alignment is needed.
#include "core/eval/alignment.h"
#include "core/io/trajectory.h"

#include <Eigen/Geometry>

#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace rrg::eval {

struct TrajectoryEvalParams {
  double max_time_difference = 0.02;  // s, association window (associate.py --max_difference)
  double rpe_delta = 1.0;             // s, Δ between the two poses of an RPE pair
  bool with_scale = false;            // Sim(3) alignment (monocular only); rigid SE(3) otherwise
};

struct AteResult {
  size_t matched = 0;       // associated pose pairs used
  bool with_scale = false;  // which alignment: false = rigid, true = similarity (s free)
  Similarity3 alignment;    // estimated → reference
  double rmse_cm = 0.0;     // after alignment
  double mean_cm = 0.0;
  double median_cm = 0.0;
  double max_cm = 0.0;
  double rmse_unaligned_cm = 0.0;  // raw positions, no alignment at all
};

struct RpeResult {
  double delta_s = 1.0;  // Δ
  size_t pairs = 0;      // 0 when the trajectory is shorter than Δ; the errors are then NaN
  double trans_rmse_cm = std::numeric_limits<double>::quiet_NaN();  // cm per Δ
  double rot_rmse_deg = std::numeric_limits<double>::quiet_NaN();   // degrees per Δ
};

struct TrajectoryMetrics {
  size_t est_poses = 0;
  size_t ref_poses = 0;
  AteResult ate;
  RpeResult rpe;
};

// ATE of matched positions (est[k] ↔ ref[k]); throws std::invalid_argument for < 3 pairs.
AteResult absolute_trajectory_error(std::span<const Eigen::Vector3d> est,
                                    std::span<const Eigen::Vector3d> ref, bool with_scale = false);

// RPE of matched poses at ascending timestamps t; est translations are multiplied by `scale`
// (the ATE's s when a Sim(3) alignment was asked for). A pair (i, j) is kept when j > i and
// |t_j − t_i − Δ| is at most half the median frame interval, so the tail shorter than Δ is dropped.
RpeResult relative_pose_error(std::span<const double> t, std::span<const Eigen::Isometry3d> est,
                              std::span<const Eigen::Isometry3d> ref, double delta_s,
                              double scale = 1.0);

// The fewest matched poses a rigid (or similarity) alignment, and so an ATE, needs.
inline constexpr size_t kMinAlignedPoses = 3;

// Associates, then ATE and RPE. Throws std::runtime_error when fewer than kMinAlignedPoses match.
TrajectoryMetrics evaluate_trajectory(const io::Trajectory& est, const io::Trajectory& ref,
                                      const TrajectoryEvalParams& params = {});

// Rotation angle of R in radians, accurate for small angles (atan2 of sin and cos).
double rotation_angle(const Eigen::Matrix3d& R);

}  // namespace rrg::eval
