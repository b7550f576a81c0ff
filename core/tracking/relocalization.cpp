#include "core/tracking/relocalization.h"

#include "core/tracking/feature_matching.h"
#include "core/tracking/motion_ba.h"

#include <Eigen/Geometry>

#include <random>

namespace rrg {
namespace {

// Rigid transform taking src columns onto dst columns (least squares).
Eigen::Isometry3d rigid_fit(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = Eigen::umeyama(src, dst, false);
  return T;
}

}  // namespace

RelocResult relocalise(const OrbFrame& frame, const KeyframeSet& keyframes, const Intrinsics& K,
                       const TrackingParams& params) {
  RelocResult best;
  const RelocParams& rp = params.reloc;
  const double thr2 = double(rp.inlier_distance_m) * rp.inlier_distance_m;
  std::mt19937 rng(12345);
  for (const Keyframe* kf : keyframes.recent(rp.max_keyframes)) {
    const std::vector<FeatureMatch> matches = match_brute_force(frame, *kf, params.orb);
    const int n = int(matches.size());
    if (n < rp.min_inliers) continue;
    Eigen::Matrix3Xd src(3, n), dst(3, n);
    for (int i = 0; i < n; ++i) {
      src.col(i) = frame.points_cam[size_t(matches[size_t(i)].keypoint)].cast<double>();
      dst.col(i) = matches[size_t(i)].X_w.cast<double>();
    }
    std::uniform_int_distribution<int> pick(0, n - 1);
    std::vector<int> best_set;
    for (int it = 0; it < rp.ransac_iterations; ++it) {
      const int a = pick(rng), b = pick(rng), c = pick(rng);
      if (a == b || b == c || a == c) continue;
      Eigen::Matrix3d s3, d3;
      s3 << src.col(a), src.col(b), src.col(c);
      d3 << dst.col(a), dst.col(b), dst.col(c);
      if ((s3.col(1) - s3.col(0)).cross(s3.col(2) - s3.col(0)).norm() < 1e-4) continue;  // collinear
      const Eigen::Isometry3d T = rigid_fit(s3, d3);
      std::vector<int> set;
      for (int i = 0; i < n; ++i)
        if ((T * src.col(i) - dst.col(i)).squaredNorm() < thr2) set.push_back(i);
      if (set.size() > best_set.size()) best_set = std::move(set);
    }
    if (int(best_set.size()) < rp.min_inliers) continue;
    Eigen::Matrix3Xd s(3, best_set.size()), d(3, best_set.size());
    std::vector<FeatureMatch> inlier_matches;
    for (size_t k = 0; k < best_set.size(); ++k) {
      s.col(Eigen::Index(k)) = src.col(best_set[k]);
      d.col(Eigen::Index(k)) = dst.col(best_set[k]);
      inlier_matches.push_back(matches[size_t(best_set[k])]);
    }
    const Eigen::Isometry3d T0 = rigid_fit(s, d);
    const std::vector<BaObservation> obs = to_observations(frame, inlier_matches, params.orb);
    const BaResult ba = optimize_pose(obs, K, params.orb.baseline_fx, T0, params.ba);
    if (ba.inliers >= rp.min_inliers && ba.inliers > best.inliers) {
      best.ok = true;
      best.inliers = ba.inliers;
      best.T_wc = ba.T_wc.cast<float>();
      best.keyframe_id = kf->id;
    }
  }
  return best;
}

}  // namespace rrg
