#pragma once
// Least-squares plane fitting from accumulated first and second moments (the cell-wise PCA of
// CAPE): moments add, so cells, regions and global planes merge exactly without their points.
#include "core/planes/plane_types.h"

#include <Eigen/Core>

#include <cstdint>

namespace rrg {

struct PlaneStateIo;

class PlaneMoments {
 public:
  void add(const Eigen::Vector3f& p) { add(double(p.x()), double(p.y()), double(p.z())); }
  void add(const Eigen::Vector3d& p) { add(p.x(), p.y(), p.z()); }
  void add(double x, double y, double z) {  // inline: the per-pixel hot path
    ++count_;
    s_[0] += x, s_[1] += y, s_[2] += z;
    s_[3] += x * x, s_[4] += x * y, s_[5] += x * z, s_[6] += y * y, s_[7] += y * z, s_[8] += z * z;
  }
  void merge(const PlaneMoments& o);
  int64_t count() const { return count_; }
  Eigen::Vector3d mean() const;        // centroid
  Eigen::Matrix3d covariance() const;  // population covariance (divided by count)

 private:
  friend struct PlaneStateIo;  // snapshots (plane_state_io.h)
  int64_t count_ = 0;
  double s_[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};  // Σx Σy Σz Σxx Σxy Σxz Σyy Σyz Σzz
};

struct PlaneFit {
  Plane plane;                        // normal = eigenvector of the smallest eigenvalue
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  float mse = 0.0f;                   // λ_min: mean squared point-to-plane distance
  float curvature = 0.0f;             // λ_min / (λ_0 + λ_1 + λ_2)
  bool valid = false;                 // at least 3 points and a non-degenerate spread
};

// PCA plane of the moments; the normal is oriented towards `viewpoint` (n·(viewpoint - c) > 0).
PlaneFit fit_plane(const PlaneMoments& m, const Eigen::Vector3f& viewpoint = Eigen::Vector3f::Zero());

}  // namespace rrg
