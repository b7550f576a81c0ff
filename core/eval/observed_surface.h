#pragma once
// Which samples of a ground-truth surface the input frames observed, so that completion scores the
// surface a run could have reconstructed (the unseen-region culling of NICE-SLAM's and Co-SLAM's
// mesh evaluations). A sample q counts as observed when at least one frame saw it: q projects to
// a pixel inside the image, in front of the camera, and that pixel's measured depth lies within
// `tolerance_m` of q's depth, so q is the first surface along the pixel's ray and not a surface
// hidden behind it (or outside the sensor's range, where the depth is 0); and, when the samples carry
// their surface's outward normals, q's side faces the camera: the back of a shelf board or of a panel
// against a wall lies within the tolerance of the face the sensor measured, yet no camera saw it.
#include "core/common/camera.h"
#include "core/common/image.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <span>
#include <vector>

namespace rrg::eval {

class ObservedSurface {
 public:
  // tolerance_m must be positive; normals empty (no facing test) or one per point (throws
  // std::invalid_argument otherwise).
  ObservedSurface(std::span<const Eigen::Vector3f> points, double tolerance_m,
                  std::span<const Eigen::Vector3f> normals = {});

  // Marks the samples frame (depth in metres, 0 = no measurement; K; camera-to-world T_wc) observes.
  // Throws std::invalid_argument when the depth image and K disagree in size.
  void observe(const DepthImage& depth, const Intrinsics& K, const Eigen::Isometry3d& T_wc);

  size_t observed() const;  // how many samples are marked
  size_t size() const { return points_.size(); }
  std::vector<Eigen::Vector3f> observed_points() const;

 private:
  std::vector<Eigen::Vector3f> points_;
  std::vector<Eigen::Vector3f> normals_;  // [points_] or empty
  std::vector<uint8_t> seen_;
  double tolerance_m_;
};

}  // namespace rrg::eval
