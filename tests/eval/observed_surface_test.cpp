// Which ground-truth samples count as observed (completion on the seen surface), with known answers.
#include "core/eval/observed_surface.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <stdexcept>
#include <vector>

namespace rrg::eval {
namespace {

Intrinsics camera() {
  Intrinsics K;
  K.fx = K.fy = 100.0f;
  K.cx = 49.5f;
  K.cy = 39.5f;
  K.width = 100;
  K.height = 80;
  return K;
}

// A wall at z = 2 m fills the view of the identity camera, except a square occluder at z = 1 m over
// pixels x, y in [40, 60) and no measurement for x >= 90.
DepthImage depth_with_occluder() {
  DepthImage d(100, 80, 2.0f);
  for (int y = 40; y < 60; ++y)
    for (int x = 40; x < 60; ++x) d(x, y) = 1.0f;
  for (int y = 0; y < 80; ++y)
    for (int x = 90; x < 100; ++x) d(x, y) = 0.0f;
  return d;
}

// The wall point seen at pixel (x, y).
Eigen::Vector3f wall_point(const Intrinsics& K, int x, int y) { return K.unproject(float(x), float(y), 2.0f); }

TEST(ObservedSurface, VisibleOccludedOutOfViewAndUnmeasured) {
  const Intrinsics K = camera();
  const std::vector<Eigen::Vector3f> pts = {
      wall_point(K, 10, 10),                    // seen
      wall_point(K, 50, 50),                    // behind the occluder
      K.unproject(50.0f, 50.0f, 1.0f),          // the occluder's front: seen
      wall_point(K, 95, 10),                    // no depth there
      Eigen::Vector3f(0.0f, 0.0f, -1.0f),       // behind the camera
      Eigen::Vector3f(5.0f, 0.0f, 2.0f),        // outside the image
      wall_point(K, 20, 20) + Eigen::Vector3f(0, 0, 0.04f),  // 4 cm off the measured depth: seen
      wall_point(K, 20, 20) + Eigen::Vector3f(0, 0, 0.30f),  // 30 cm behind the wall: hidden
  };
  ObservedSurface seen(pts, 0.05);
  seen.observe(depth_with_occluder(), K, Eigen::Isometry3d::Identity());
  const std::vector<Eigen::Vector3f> got = seen.observed_points();
  ASSERT_EQ(got.size(), 3u);
  EXPECT_TRUE(got[0].isApprox(pts[0]));
  EXPECT_TRUE(got[1].isApprox(pts[2]));
  EXPECT_TRUE(got[2].isApprox(pts[6]));
  EXPECT_EQ(seen.observed(), 3u);
  EXPECT_EQ(seen.size(), pts.size());
}

TEST(ObservedSurface, AnotherFrameRevealsWhatTheFirstMissed) {
  const Intrinsics K = camera();
  const Eigen::Vector3f hidden = wall_point(K, 50, 50);
  ObservedSurface seen(std::vector<Eigen::Vector3f>{hidden}, 0.05);
  seen.observe(depth_with_occluder(), K, Eigen::Isometry3d::Identity());
  EXPECT_EQ(seen.observed(), 0u);
  // The camera moved 0.5 m to the right (+x in the world): the point is now at pixel x = 25 of a
  // wall view with no occluder there. Marks stay once set.
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  T_wc.translation() = Eigen::Vector3d(0.5, 0.0, 0.0);
  seen.observe(DepthImage(100, 80, 2.0f), K, T_wc);
  EXPECT_EQ(seen.observed(), 1u);
  seen.observe(DepthImage(100, 80, 0.0f), K, Eigen::Isometry3d::Identity());
  EXPECT_EQ(seen.observed(), 1u);
}

// A panel 2 cm thick at z = 1.98 .. 2.0 m in front of the wall (camera at the origin looking +z):
// its front face (normal −z, towards the camera) is measured; its back face, 2 cm behind that,
// passes the 5 cm depth test but faces away from the camera, so with normals it is not observed.
TEST(ObservedSurface, FacesTurnedAwayFromTheCameraAreNotObserved) {
  const Intrinsics K = camera();
  DepthImage d(100, 80, 1.98f);
  const Eigen::Vector3f front = K.unproject(30.0f, 30.0f, 1.98f), back = K.unproject(30.0f, 30.0f, 2.0f);
  const std::vector<Eigen::Vector3f> pts = {front, back};
  const std::vector<Eigen::Vector3f> normals = {-Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitZ()};
  ObservedSurface depth_only(pts, 0.05);
  depth_only.observe(d, K, Eigen::Isometry3d::Identity());
  EXPECT_EQ(depth_only.observed(), 2u);
  ObservedSurface facing(pts, 0.05, normals);
  facing.observe(d, K, Eigen::Isometry3d::Identity());
  ASSERT_EQ(facing.observed(), 1u);
  EXPECT_TRUE(facing.observed_points()[0].isApprox(front));
  // Seen from behind the panel (camera at z = 4 m looking −z), the back face is the visible one.
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
  T_wc.linear() = Eigen::AngleAxisd(3.14159265358979, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_wc.translation() = Eigen::Vector3d(0.0, 0.0, 4.0);
  const Eigen::Vector3f back_cam = (T_wc.inverse().cast<float>() * back);
  DepthImage d2(100, 80, back_cam.z());
  facing.observe(d2, K, T_wc);
  EXPECT_EQ(facing.observed(), 2u);
}

TEST(ObservedSurface, BadInputIsNamed) {
  const std::vector<Eigen::Vector3f> pts = {Eigen::Vector3f(0, 0, 1)};
  EXPECT_THROW(ObservedSurface(pts, 0.0), std::invalid_argument);
  EXPECT_THROW(ObservedSurface(pts, -1.0), std::invalid_argument);
  const std::vector<Eigen::Vector3f> two_normals = {Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitZ()};
  EXPECT_THROW(ObservedSurface(pts, 0.05, two_normals), std::invalid_argument);
  ObservedSurface seen(pts, 0.05);
  try {
    seen.observe(DepthImage(10, 10, 1.0f), camera(), Eigen::Isometry3d::Identity());
    FAIL() << "a depth image of another size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("10x10"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rrg::eval
