#pragma once
// ORB features of a frame (OpenCV ORB) for stage 2 of tracking (paper §4.1.2): detection only on
// pixels where the tracking mask R_k^track is 0, and each keypoint's camera-frame point from depth.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/tracking/tracking_params.h"

#include <opencv2/core.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
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
// Depth (metres, registered to colour) gives each keypoint its point p_c = D(u) K⁻¹[u, 1]ᵀ, unless
// the keypoint sits on a depth edge (on_depth_edge, OrbParams::max_depth_range): then z = 0.
// Throws std::invalid_argument when the image, depth, mask and K sizes differ.
OrbFrame extract_orb(const ColorImage& color, const DepthImage& depth, const Intrinsics& K,
                     const MaskImage* exclude, const OrbParams& params);

// Whether the valid depths in the (2·half + 1)² window around (x, y) span more than max_range ·
// D(x, y), D(x, y) valid: an occlusion corner or silhouette rather than one surface point. Pixels
// without depth are no evidence either way.
bool on_depth_edge(const DepthImage& depth, int x, int y, int half, float max_range);

// OpenCV's ORB reports a keypoint found on pyramid level l at s_l·x_l, s_l = f^l, as if level l's
// pixel x_l covered level 0 from s_l·x_l. Its levels are resized with pixel centres at x + 0.5 and
// rounded sizes W_l = round(W / s_l), so x_l's centre is at (x_l + 0.5)·W / W_l − 0.5 on level 0:
// at 320x240 the reported point is 0.1 px off at level 1 and 1.3–2.6 px at level 7, the same way
// in every frame, so a point seen at different levels in two frames moves. This maps OpenCV's
// coordinates (octave ≥ 1) to level-0 pixel centres in place; extract_orb applies it.
void to_level0_pixels(std::vector<cv::KeyPoint>& keypoints, int width, int height, float scale_factor);

// s_l = f^l of pyramid level l = max(0, octave) (OpenCV's layer scale, computed in double as OpenCV
// does): the keypoint's patch, search radius and pixel noise all grow with it.
inline double level_scale(float scale_factor, int octave) {
  return std::pow(double(scale_factor), double(std::max(0, octave)));
}

// Hamming distance of two 32-byte ORB descriptors.
int hamming_distance(const uint8_t* a, const uint8_t* b);

}  // namespace rrg
