#pragma once
// ORB features of a frame (OpenCV ORB) for stage 2 of tracking (paper §4.1.2): detection only on
// pixels where the tracking mask R_k^track is 0, and each keypoint's camera-frame point from depth.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/tracking/tracking_params.h"

#include <opencv2/core.hpp>

#include <Eigen/Core>

#include <vector>

namespace rrg {

struct OrbFrame {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;                     // [N, 32] CV_8U
  std::vector<Eigen::Vector3f> points_cam; // [N] camera frame from D_k; z = 0 when no valid depth
};

// 8-bit grey of a float RGB image (ITU-R BT.601 weights).
cv::Mat to_gray8(const ColorImage& color);

// ORB on `color`; pixels with exclude(u) != 0 (dilated by half an ORB patch) get no keypoint.
// Depth (metres, registered to colour) gives each keypoint its point p_c = D(u) K⁻¹[u, 1]ᵀ.
// Throws std::invalid_argument when the image, depth, mask and K sizes differ.
OrbFrame extract_orb(const ColorImage& color, const DepthImage& depth, const Intrinsics& K,
                     const MaskImage* exclude, const OrbParams& params);

// Hamming distance of two 32-byte ORB descriptors.
int hamming_distance(const uint8_t* a, const uint8_t* b);

}  // namespace rrg
