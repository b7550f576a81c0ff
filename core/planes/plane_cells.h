#pragma once
// Internal to plane segmentation: the organised point cloud and the cell-wise PCA fits of CAPE
// (step 1 of core/planes/plane_segmentation.h).
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/planes/plane_fit.h"
#include "core/planes/plane_segmentation.h"

#include <Eigen/Core>

#include <vector>

namespace rrg::planes_detail {

// Camera-frame points of a depth map; invalid pixels hold z = 0.
Image<Eigen::Vector3f> organised_points(const DepthImage& depth, const Intrinsics& K);

struct CellGrid {
  int size = 0, nx = 0, ny = 0;       // cell side (pixels), cells per row / column
  std::vector<PlaneMoments> moments;  // [ny * nx] of the cell's valid points
  std::vector<PlaneFit> fits;         // [ny * nx]
  std::vector<uint8_t> planar;        // [ny * nx] passed the planarity test
  std::vector<float> depth;           // [ny * nx] mean depth of the valid points

  int index(int cx, int cy) const { return cy * nx + cx; }
  int x0(int cx) const { return cx * size; }
  int y0(int cy) const { return cy * size; }
};

// Step 1: fits every cell and runs the planarity test.
CellGrid fit_cells(const Image<Eigen::Vector3f>& points, const PlaneSegmentationParams& params);

}  // namespace rrg::planes_detail
