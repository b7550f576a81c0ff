#include "core/tracking/orb_features.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace rrg {
namespace {

constexpr int kMaskDilatePx = 7;  // half of OpenCV ORB's 31-pixel patch, rounded down to the FAST radius

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

bool on_depth_edge(const DepthImage& depth, int x, int y, int half, float max_range) {
  const float z = depth(x, y);
  float lo = z, hi = z;
  for (int v = std::max(0, y - half); v <= std::min(depth.height() - 1, y + half); ++v)
    for (int u = std::max(0, x - half); u <= std::min(depth.width() - 1, x + half); ++u) {
      const float d = depth(u, v);
      if (!(d > 0.0f)) continue;  // no measurement: no evidence either way
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  return hi - lo > max_range * z;
}

void to_level0_pixels(std::vector<cv::KeyPoint>& keypoints, int width, int height, float scale_factor) {
  for (cv::KeyPoint& kp : keypoints) {
    if (kp.octave <= 0) continue;
    // OpenCV's level l: s_l = (float) f^l, size (cvRound(W / s_l), cvRound(H / s_l)), each level
    // resized from the one before with pixel centres at x + 0.5, then pt = s_l x_l.
    const float s = float(level_scale(scale_factor, kp.octave));
    const int wl = cvRound(float(width) / s), hl = cvRound(float(height) / s);
    const float xl = kp.pt.x / s, yl = kp.pt.y / s;
    kp.pt.x = (xl + 0.5f) * (float(width) / float(wl)) - 0.5f;
    kp.pt.y = (yl + 0.5f) * (float(height) / float(hl)) - 0.5f;
  }
}

cv::Mat to_gray8(const ColorImage& color) {
  cv::Mat gray(color.height(), color.width(), CV_8U);
  for (int y = 0; y < color.height(); ++y) {
    uint8_t* row = gray.ptr<uint8_t>(y);
    for (int x = 0; x < color.width(); ++x) {
      const Color& c = color(x, y);
      const float g = 0.299f * c.x() + 0.587f * c.y() + 0.114f * c.z();
      row[x] = uint8_t(std::clamp(std::lround(g * 255.0f), 0L, 255L));
    }
  }
  return gray;
}

OrbFrame extract_orb(const ColorImage& color, const DepthImage& depth, const Intrinsics& K,
                     const MaskImage* exclude, const OrbParams& params) {
  if (color.width() != K.width || color.height() != K.height || !color.same_size(depth))
    throw std::invalid_argument("extract_orb: colour " + size_text(color.width(), color.height()) + ", depth " +
                                size_text(depth.width(), depth.height()) + " and intrinsics " + K.to_string() +
                                " must have one size");
  if (exclude && !exclude->same_size(color))
    throw std::invalid_argument("extract_orb: tracking mask is " + size_text(exclude->width(), exclude->height()) +
                                " but the image is " + size_text(color.width(), color.height()));
  const cv::Mat gray = to_gray8(color);
  cv::Mat allowed;
  if (exclude) {
    cv::Mat ex(exclude->height(), exclude->width(), CV_8U);
    for (int y = 0; y < ex.rows; ++y)
      for (int x = 0; x < ex.cols; ++x) ex.at<uint8_t>(y, x) = (*exclude)(x, y) ? 255 : 0;
    cv::dilate(ex, ex, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kMaskDilatePx + 1, 2 * kMaskDilatePx + 1)));
    cv::bitwise_not(ex, allowed);
  }
  const int edge = std::max(4, std::min({31, color.width() / 8, color.height() / 8}));
  cv::Ptr<cv::ORB> orb = cv::ORB::create(params.features, params.scale_factor, params.levels, edge, 0, 2,
                                         cv::ORB::HARRIS_SCORE, std::min(31, edge), 20);
  OrbFrame f;
  orb->detectAndCompute(gray, allowed, f.keypoints, f.descriptors);
  to_level0_pixels(f.keypoints, color.width(), color.height(), params.scale_factor);
  f.points_cam.resize(f.keypoints.size(), Eigen::Vector3f::Zero());
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const int x = int(std::lround(f.keypoints[i].pt.x)), y = int(std::lround(f.keypoints[i].pt.y));
    if (x < 0 || y < 0 || x >= depth.width() || y >= depth.height()) continue;
    const float z = depth(x, y);
    if (!(z >= params.min_depth_m && z <= params.max_depth_m)) continue;
    if (params.max_depth_range > 0.0f) {
      // the window a keypoint of level l describes grows as 1.2^l (OpenCV's patch is 31 px on its level)
      const int half = std::max(1, int(std::lround(level_scale(params.scale_factor, f.keypoints[i].octave))));
      if (on_depth_edge(depth, x, y, half, params.max_depth_range)) continue;
    }
    f.points_cam[i] = K.unproject(f.keypoints[i].pt.x, f.keypoints[i].pt.y, z);
  }
  return f;
}

int hamming_distance(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int k = 0; k < 32; k += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}

}  // namespace rrg
