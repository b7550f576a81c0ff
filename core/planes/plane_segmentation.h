#pragma once
// CAPE-class depth plane segmentation (Proença & Gao 2018, paper §4.1.3), CPU only like CAPE:
//  1. cell-wise PCA plane fits on a regular grid of the organised point cloud, with a planarity
//     test (valid depth, no depth jump along the cell's middle row/column, fit RMS within the
//     sensor's noise);
//  2. region growing seeded from the most populated bin of a histogram of cell normals (polar,
//     azimuth), comparing neighbour cells with the region's plane (refitted as the region grows);
//  3. merging of adjacent regions whose planes agree (normal angle and centroid distances);
//  4. pixel-level boundary refinement: pixels of a region's cells and of the one-cell ring around
//     them take the nearest plane within the distance threshold; slivers between planes (crease
//     cells) are dropped and the pixels refined again.
// Output: the per-pixel local plane map and the plane parameters (n, b) refitted to the pixels.
#include "core/common/camera.h"
#include "core/common/depth_noise_model.h"
#include "core/common/image.h"
#include "core/planes/plane_types.h"

#include <string>

namespace rrg {

struct PlaneSegmentationParams {
  int cell_size = 0;                 // cell side in pixels; 0 = width / 40 (16 px at 640x480; CAPE uses
                                     // 20 for Kinect noise; smaller cells keep 8 cm strips at 3 m)
  float min_valid_ratio = 0.5f;      // a cell needs this fraction of pixels with depth
  // Sensor axial noise σ_n(z) = a + b (z − z0)², metres: Kinect v1 (Nguyen, Izadi & Lovell 2012),
  // the class of RGB-D sensors the paper and CAPE target. It bounds the cell fit (RMS < planar_sigmas
  // σ_n, or σ(z) below when larger) and widens the pixel refinement to refine_distance_sigmas σ_n.
  DepthNoiseModel noise;
  float planar_sigmas = 2.0f;
  float sigma_min = 0.002f;          // σ_min, metres: floor of the distance scale σ(z) below
  float sigma_k = 0.001f;            // k_σ, 1/m: σ(z) = max(σ_min, k_σ z²): growing and merging distances
  float jump_ratio = 0.03f;          // depth jump between neighbours along a cell's middle lines > ratio·z: not planar
  int histogram_bins = 20;           // bins per axis of the normal histogram (polar, azimuth)
  float grow_angle_deg = 12.0f;      // neighbour normal vs seed normal during growing
  float grow_distance_sigmas = 2.5f; // neighbour centroid to the seed plane: within this many σ(z)
  float min_grow_distance = 0.01f;   // ... and never less than this, metres
  int min_region_cells = 4;          // smaller regions are dropped
  float merge_angle_deg = 10.0f;     // adjacent regions merge when normals agree within this
  float merge_distance = 0.01f;      // ... and each centroid lies within max(this, 3 σ(z)) of the other plane
  float refine_distance_sigmas = 2.5f;  // pixel-level assignment: |n·p + b| < max(min_refine, this·max(σ, σ_n))
  float min_refine_distance = 0.01f;
  int min_plane_pixels = 0;          // after refinement; 0 = 2 cells' worth of pixels

  void validate() const;             // throws std::invalid_argument naming the bad field
  std::string to_string() const;
  float sigma(float z) const { return std::max(sigma_min, sigma_k * z * z); }
  float noise_sigma(float z) const { return noise.sigma(z); }
  float planar_rms(float z) const { return std::max(sigma(z), planar_sigmas * noise_sigma(z)); }
  // Coplanarity of two regions (step 3, and LocalPlane::same_plane_distance): centroid-to-plane distance.
  float merge_tolerance(float z) const { return std::max(merge_distance, 3.0f * sigma(z)); }
  float refine_distance(float z) const {
    return std::max(min_refine_distance, refine_distance_sigmas * std::max(sigma(z), noise_sigma(z)));
  }
};

// Segments a depth map (metres, 0 = invalid) of a camera with intrinsics K (same size; throws
// std::invalid_argument otherwise). Local plane ids are 1..K, largest plane first.
PlaneSegmentation segment_planes(const DepthImage& depth, const Intrinsics& K,
                                 const PlaneSegmentationParams& params = {});

}  // namespace rrg
