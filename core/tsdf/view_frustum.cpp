#include "core/tsdf/view_frustum.h"

#include "core/tsdf/voxel.h"

#include <cmath>

namespace rrg {

ViewFrustum::ViewFrustum(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const TsdfParams& params)
    : voxel_size_(params.voxel_size) {
  // Camera frame: the image edges half a pixel beyond the outer pixel centres, x/z in [x0, x1],
  // y/z in [y0, y1]; depth in [min_depth, max_depth].
  const float x0 = (-0.5f - K.cx) / K.fx, x1 = (float(K.width) - 0.5f - K.cx) / K.fx;
  const float y0 = (-0.5f - K.cy) / K.fy, y1 = (float(K.height) - 0.5f - K.cy) / K.fy;
  const std::array<Eigen::Vector4f, 6> camera = {
      Eigen::Vector4f(1, 0, -x0, 0),  // x - x0 z >= 0
      Eigen::Vector4f(-1, 0, x1, 0),  // x1 z - x >= 0
      Eigen::Vector4f(0, 1, -y0, 0),
      Eigen::Vector4f(0, -1, y1, 0),
      Eigen::Vector4f(0, 0, 1, -params.min_depth),
      Eigen::Vector4f(0, 0, -1, params.max_depth),
  };
  const Eigen::Matrix3f R = T_wc.linear();
  const Eigen::Vector3f t = T_wc.translation();
  for (size_t i = 0; i < camera.size(); ++i) {
    // n_c·p_c + d = n_c·R^T (p_w - t) + d: n_w = R n_c, d_w = d - n_w·t
    const Eigen::Vector3f n_c = camera[i].head<3>();
    const float norm = n_c.norm();
    const Eigen::Vector3f n_w = R * (n_c / norm);
    planes_[i] << n_w, camera[i].w() / norm - n_w.dot(t);
  }
  // A block's voxels lie within its half diagonal of its centre; a sample reads voxels up to two
  // voxels from its point (trilinear corners, then the gradient's neighbours); one more for slack.
  margin_ = (0.5f * std::sqrt(3.0f) * float(kBlockSide) + 3.0f) * params.voxel_size;
}

bool ViewFrustum::may_read(const Eigen::Vector3i& coord) const {
  const Eigen::Vector3f c = block_center(coord, voxel_size_);
  for (const Eigen::Vector4f& p : planes_)
    if (p.head<3>().dot(c) + p.w() < -margin_) return false;
  return true;
}

}  // namespace rrg
