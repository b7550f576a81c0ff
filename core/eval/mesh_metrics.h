#pragma once
// Geometry accuracy of a reconstructed mesh against the ground-truth surface, as NICE-SLAM
// (Zhu et al. 2022, eval_recon.py) without its unseen-region culling:
//   sample N points uniformly by area on each mesh (surface_sampling.h; point clouds use their
//   vertices), then with d(p, X) = distance from p to the nearest sample of X:
//   accuracy        = mean over est samples p of d(p, ref)   (cm)
//   completion      = mean over ref samples q of d(q, est)   (cm)
//   accuracy ratio  = fraction of est samples with d(p, ref) < τ
//   completion ratio= fraction of ref samples with d(q, est) < τ   (τ = 3 cm)
// The estimated mesh is sampled with `seed`, the reference with `seed + 1` (independent samples,
// so identical meshes give the sampling floor, not an exact 0).
#include "core/common/mesh.h"
#include "core/eval/kd_tree.h"

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace rrg::eval {

struct MeshEvalParams {
  size_t samples = 200000;  // N per mesh (NICE-SLAM: 200k)
  double threshold = 0.03;  // τ, metres
  uint64_t seed = 0;        // sampling seed (fixed: runs are deterministic)
};

struct MeshMetrics {
  size_t est_samples = 0;
  size_t ref_samples = 0;
  double threshold_m = 0.03;
  double accuracy_cm = 0.0;
  double completion_cm = 0.0;
  double accuracy_ratio = 0.0;    // in [0, 1]
  double completion_ratio = 0.0;  // in [0, 1]
};

// Distance (m) from every query to its nearest tree point; OpenMP-parallel.
std::vector<double> nearest_distances(const KdTree& tree, std::span<const Eigen::Vector3f> queries);

// The metrics on given point samples. Throws std::invalid_argument on an empty set or τ ≤ 0.
MeshMetrics evaluate_point_sets(std::span<const Eigen::Vector3f> est, std::span<const Eigen::Vector3f> ref,
                                double threshold = 0.03);

// Samples both meshes, then evaluate_point_sets.
MeshMetrics evaluate_mesh(const TriangleMesh& est, const TriangleMesh& ref, const MeshEvalParams& params = {});

}  // namespace rrg::eval
