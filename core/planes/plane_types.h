#pragma once
// Plane types of reflective plane identification (paper §4.1.3): an infinite plane n·p + d = 0,
// the planes CAPE-class segmentation finds in one depth map (local planes, camera frame) and the
// per-pixel local plane map.
#include "core/common/image.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rrg {

// n·p + d = 0 with |n| = 1 (planes.json of the synthetic layout uses the same convention).
struct Plane {
  Eigen::Vector3f n = Eigen::Vector3f::UnitZ();
  float d = 0.0f;

  float signed_distance(const Eigen::Vector3f& p) const { return n.dot(p) + d; }
  // The same plane in another frame: T maps points of this plane's frame into the new frame.
  template <class Transform>
  Plane transformed(const Transform& T) const {
    const Eigen::Vector3f n2 = (T.linear() * n).normalized();
    return {n2, d - n2.dot(T.translation())};
  }
};

// One plane found in a depth map (camera frame, normal facing the camera: d > 0).
struct LocalPlane {
  int id = 0;                          // label in PlaneSegmentation::labels, 1..K
  Plane plane;                         // (n, b) fitted to the plane's pixels
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  int64_t pixels = 0;                  // labelled pixels
  float rms = 0.0f;                    // RMS point-to-plane distance of those pixels, metres
  // The segmenter's coplanarity tolerance at this plane's depth, max(merge_distance, 3 σ(z)): two
  // planes of one depth map are one surface only when each centroid lies this close to the other.
  float same_plane_distance = 0.01f;
  // The segmenter's planarity bound at this plane's depth, max(σ(z), 2 σ_n(z)): the RMS residual a
  // planar patch of the sensor's noise stays under (a cell's planarity test).
  float planar_rms = 0.01f;
};

struct PlaneSegmentation {
  LabelImage labels;                   // local plane id per pixel, 0 = none
  std::vector<LocalPlane> planes;      // planes[i].id == i + 1, largest first
  int cells_x = 0, cells_y = 0;        // the cell grid used
  int planar_cells = 0;                // cells that passed the planarity test
};

}  // namespace rrg
