#pragma once
// The part of the volume a camera's raycast reads (tsdf_raycast.h): its rays through the image
// between min_depth and max_depth (z-depth, as the raycast marches), widened by the voxels a
// sample reads around itself (trilinear corners, the normal's gradient). Streaming uses it to
// bring back exactly the blocks a view needs (docs/tsdf.md "Streaming in a session").
#include "core/common/camera.h"
#include "core/tsdf/tsdf_params.h"

#include <Eigen/Geometry>

#include <array>

namespace rrg {

class ViewFrustum {
 public:
  ViewFrustum(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const TsdfParams& params);
  // Whether a raycast of this camera may read a voxel of block `coord`: false only when the whole
  // block lies farther than the read margin outside one of the frustum's six planes.
  bool may_read(const Eigen::Vector3i& coord) const;

 private:
  std::array<Eigen::Vector4f, 6> planes_;  // world frame, n·p + d >= 0 inside, |n| = 1
  float voxel_size_ = 0.0f;
  float margin_ = 0.0f;  // half a block's diagonal + the voxels a sample reads beyond its point
};

}  // namespace rrg
