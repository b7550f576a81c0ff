// ORB keypoints in level-0 pixel coordinates at every pyramid level (to_level0_pixels), and no depth
// for keypoints on depth edges (on_depth_edge).
#include "core/tracking/orb_features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

namespace rrg {
namespace {

// Grey rectangles of 4 to 120 px, one over the other: corners at every scale of the pyramid.
ColorImage rectangles(int width, int height, uint32_t seed) {
  ColorImage img(width, height, Color::Constant(0.5f));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int k = 0; k < 600; ++k) {
    const int w = 4 + int(116 * unit(rng) * unit(rng)), h = 4 + int(116 * unit(rng) * unit(rng));
    const int x0 = int(unit(rng) * float(width - w)), y0 = int(unit(rng) * float(height - h));
    const float g = unit(rng);
    for (int y = y0; y < y0 + h; ++y)
      for (int x = x0; x < x0 + w; ++x) img(x, y) = Color::Constant(g);
  }
  return img;
}

ColorImage flipped(const ColorImage& img, bool horizontal) {
  ColorImage out(img.width(), img.height());
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      out(x, y) = horizontal ? img(img.width() - 1 - x, y) : img(x, img.height() - 1 - y);
  return out;
}

// A mirrored image must give mirrored keypoints: OpenCV's pyramid (centre-aligned bilinear
// resizing) and FAST/Harris are symmetric under a flip, so a corner at level-0 pixel x in one
// image is at W − 1 − x in the other, at every level, only when the coordinates are level-0 pixel
// centres. OpenCV's own s_l·x_l misses the mirror by 0.3 to 3 px, depending on the level,
// at 640x480; this test fails without to_level0_pixels.
TEST(OrbFeatures, KeypointsOfAMirroredImageAreMirroredAtEveryLevel) {
  const int W = 640, H = 480;
  const Intrinsics K{500.0f, 500.0f, 319.5f, 239.5f, W, H};
  const DepthImage depth(W, H, 1.0f);
  OrbParams params;
  const ColorImage a = rectangles(W, H, 7);
  const OrbFrame fa = extract_orb(a, depth, K, nullptr, params);
  for (const bool horizontal : {true, false}) {
    SCOPED_TRACE(horizontal ? "left-right flip" : "up-down flip");
    const OrbFrame fb = extract_orb(flipped(a, horizontal), depth, K, nullptr, params);
    std::map<int, int> total, mirrored;
    for (const cv::KeyPoint& p : fa.keypoints) {
      const float mx = horizontal ? float(W - 1) - p.pt.x : p.pt.x;
      const float my = horizontal ? p.pt.y : float(H - 1) - p.pt.y;
      ++total[p.octave];
      for (const cv::KeyPoint& q : fb.keypoints)
        if (q.octave == p.octave && std::abs(q.pt.x - mx) < 0.02f && std::abs(q.pt.y - my) < 0.02f) {
          ++mirrored[p.octave];
          break;
        }
    }
    int levels_checked = 0;
    for (const auto& [octave, n] : total) {
      if (n < 10) continue;
      ++levels_checked;
      // Ties in the Harris ranking and the border rule may change a few keypoints, not most.
      EXPECT_GE(mirrored[octave], 0.7 * n) << "octave " << octave << ": " << mirrored[octave] << " of " << n
                                           << " keypoints have a mirror image within 0.02 px";
    }
    EXPECT_GE(levels_checked, 6);
  }
}

// The mapping by hand at 320x240, level 7: s = 1.2^7 = 3.5832, level size 89 x 67; OpenCV's
// x_7 = 44 (reported 157.66) is the centre of level-0 pixels (44.5) · 320 / 89 − 0.5 = 159.50.
TEST(OrbFeatures, LevelCoordinatesMapToLevelZeroPixelCentres) {
  const float s7 = float(std::pow(1.2, 7.0));
  std::vector<cv::KeyPoint> kps(3);
  kps[0].pt = {44.0f * s7, 10.0f * s7};
  kps[0].octave = 7;
  kps[1].pt = {12.0f, 34.0f};  // level 0: unchanged
  kps[1].octave = 0;
  kps[2].pt = {0.0f, 0.0f};  // level 1 (267 x 200): pixel 0's centre is at 0.5 · 320 / 267 − 0.5
  kps[2].octave = 1;
  to_level0_pixels(kps, 320, 240, 1.2f);
  EXPECT_NEAR(kps[0].pt.x, 44.5 * 320.0 / 89.0 - 0.5, 1e-4);
  EXPECT_NEAR(kps[0].pt.y, 10.5 * 240.0 / 67.0 - 0.5, 1e-4);
  EXPECT_FLOAT_EQ(kps[1].pt.x, 12.0f);
  EXPECT_FLOAT_EQ(kps[1].pt.y, 34.0f);
  EXPECT_NEAR(kps[2].pt.x, 0.5 * 320.0 / 267.0 - 0.5, 1e-5);
  EXPECT_NEAR(kps[2].pt.y, 0.5 * 240.0 / 200.0 - 0.5, 1e-5);
}

// A step in depth down the middle of a textured image (2 m left of x = 319.5, 3 m right of it):
// every keypoint whose window (half-width max(1, round(1.2^octave)) around its rounded pixel)
// reaches across the step keeps no depth, every other keeps its side's. With the test off
// (max_depth_range = 0) the keypoints across the step take whichever side their pixel is on.
TEST(OrbFeatures, KeypointsOnADepthEdgeKeepNoDepth) {
  const int W = 640, H = 480, step = 320;
  const Intrinsics K{500.0f, 500.0f, 319.5f, 239.5f, W, H};
  DepthImage depth(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) depth(x, y) = x < step ? 2.0f : 3.0f;
  // two textures meet at x = step, as foreground and background do at an occlusion boundary: the
  // rectangles' edges end there in corners
  ColorImage img = rectangles(W, H, 11);
  const ColorImage right = rectangles(W, H, 12);
  for (int y = 0; y < H; ++y)
    for (int x = step; x < W; ++x) img(x, y) = right(x, y);
  OrbParams params;
  ASSERT_FLOAT_EQ(params.max_depth_range, 0.05f);
  const OrbFrame f = extract_orb(img, depth, K, nullptr, params);
  OrbParams off = params;
  off.max_depth_range = 0.0f;
  const OrbFrame g = extract_orb(img, depth, K, nullptr, off);
  ASSERT_EQ(f.keypoints.size(), g.keypoints.size());
  int across = 0, kept = 0;
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = f.keypoints[i];
    const int x = int(std::lround(kp.pt.x));
    const int half = std::max(1, int(std::lround(std::pow(1.2, double(kp.octave)))));
    const bool straddles = std::max(0, x - half) < step && std::min(W - 1, x + half) >= step;
    const float side = x < step ? 2.0f : 3.0f;
    if (straddles) {
      ++across;
      EXPECT_EQ(f.points_cam[i].z(), 0.0f) << "keypoint at x = " << kp.pt.x << ", octave " << kp.octave;
      EXPECT_EQ(g.points_cam[i].z(), side) << "with the test off, keypoint at x = " << kp.pt.x;
    } else {
      ++kept;
      EXPECT_EQ(f.points_cam[i].z(), side) << "keypoint at x = " << kp.pt.x << ", octave " << kp.octave;
    }
  }
  EXPECT_GE(across, 10) << "too few keypoints on the edge to test";
  EXPECT_GE(kept, 200);
}

// What is not an edge: a plane 80° oblique to the view at f = 256 (depth changes by z·tan 80° / f,
// 2.2 % of z a pixel, across the 3x3 window of level 0) and a fronto-parallel plane at 3 m with
// Kinect v1's noise at ±2σ_n (σ_n ≈ 1.4 cm there) in a checkerboard; and what is: the same plane
// at 85° (4.5 % a pixel), and a 1 cm step on a plane 10 cm away.
TEST(OrbFeatures, DepthEdgeTestKnowsAnEdgeFromASteepPlaneAndNoise) {
  const int W = 320, H = 240;
  const float f = 256.0f, cx = 159.5f, z0 = 3.0f;
  auto oblique = [&](double deg) {
    DepthImage d(W, H);
    const double t = std::tan(deg * std::acos(-1.0) / 180.0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) d(x, y) = float(z0 / (1.0 - t * (double(x) - cx) / f));
    return d;
  };
  EXPECT_FALSE(on_depth_edge(oblique(80.0), 160, 120, 1, 0.05f));
  EXPECT_TRUE(on_depth_edge(oblique(85.0), 160, 120, 1, 0.05f));
  const float sigma = 0.0012f + 0.0019f * (z0 - 0.4f) * (z0 - 0.4f);
  DepthImage noisy(W, H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) noisy(x, y) = z0 + ((x + y) % 2 ? 2.0f : -2.0f) * sigma;
  EXPECT_FALSE(on_depth_edge(noisy, 100, 100, 3, 0.05f));
  DepthImage near(W, H, 0.10f);
  for (int y = 0; y < H; ++y) near(100, y) = 0.11f;
  EXPECT_TRUE(on_depth_edge(near, 101, 50, 1, 0.05f));
  EXPECT_FALSE(on_depth_edge(near, 102, 50, 0, 0.05f));
  // pixels without depth are no evidence: a hole next to the keypoint is not an edge
  DepthImage holes(W, H, 2.0f);
  holes(51, 50) = 0.0f;
  EXPECT_FALSE(on_depth_edge(holes, 50, 50, 1, 0.05f));
}

}  // namespace
}  // namespace rrg
