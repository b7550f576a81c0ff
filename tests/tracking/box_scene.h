#pragma once
// An analytic scene for tracking tests: the inside of an axis-aligned box (plus a tilted slab so no
// direction is degenerate), rendered exactly by ray casting on the host: depth of a camera, and the
// world-frame vertex/normal maps a TSDF raycast would give.
#include "core/common/camera.h"
#include "core/common/image.h"

#include <Eigen/Geometry>

namespace rrg::test {

struct BoxRender {
  DepthImage depth;                       // metres along the optical axis
  Image<Eigen::Vector3f> vertices;        // world frame, 0 = none
  Image<Eigen::Vector3f> normals;         // world frame, facing the camera
};

// Renders the box [-2, 2]³ seen from inside by camera (K, T_wc).
BoxRender render_box(const Intrinsics& K, const Eigen::Isometry3f& T_wc);

// A camera at `position` looking at `target` (OpenCV axes, world up = +z).
Eigen::Isometry3f look_at(const Eigen::Vector3f& position, const Eigen::Vector3f& target);

// Small test intrinsics (w x h, 60° horizontal field of view).
Intrinsics test_intrinsics(int width, int height);

}  // namespace rrg::test
