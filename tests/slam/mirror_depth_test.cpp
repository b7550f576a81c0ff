// The mirrored camera of mirror_depth.h: a point in front of a mirror, seen by the mirrored camera,
// lands on the pixel (W − 1 − u, v) where the original camera sees its mirror image, at the same
// depth; and the mirrored camera is a proper rigid transform.
#include "core/slam/mirror_depth.h"

#include <gtest/gtest.h>

namespace rrg {
namespace {

TEST(MirrorDepth, MirroredCameraSeesTheVirtualPointAtTheFlippedPixel) {
  const Intrinsics K{100.0f, 110.0f, 30.0f, 22.0f, 64, 48};
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  T_wc.linear() = Eigen::AngleAxisf(0.3f, Eigen::Vector3f(0.2f, 1.0f, 0.1f).normalized()).toRotationMatrix();
  T_wc.translation() = Eigen::Vector3f(0.4f, -0.2f, 0.5f);
  const Eigen::Vector4f plane(0.1f, -0.2f, 2.0f, -5.0f);  // not unit: n·x + d = 0
  const MirroredCamera m = mirror_camera(K, T_wc, plane);
  EXPECT_NEAR(m.T_wc.linear().determinant(), 1.0f, 1e-5f);
  EXPECT_TRUE((m.T_wc.linear().transpose() * m.T_wc.linear()).isApprox(Eigen::Matrix3f::Identity(), 1e-5f));
  const Eigen::Vector3f n = plane.head<3>().normalized();
  const float d = plane.w() / plane.head<3>().norm();
  for (const Eigen::Vector3f& p_cam : {Eigen::Vector3f(0.1f, 0.05f, 1.0f), Eigen::Vector3f(-0.2f, 0.1f, 1.5f)}) {
    const Eigen::Vector3f X = T_wc * p_cam;                       // a real point, camera side
    const Eigen::Vector3f X_virtual = X - 2.0f * (n.dot(X) + d) * n;  // its mirror image
    const Eigen::Vector3f q = T_wc.inverse() * X_virtual;         // seen by the original camera
    ASSERT_GT(q.z(), 0.0f);
    const Eigen::Vector2f uv = K.project(q);
    const Eigen::Vector3f q_m = m.T_wc.inverse() * X;             // the real point, mirrored camera
    ASSERT_GT(q_m.z(), 0.0f);
    const Eigen::Vector2f uv_m = m.K.project(q_m);
    EXPECT_NEAR(uv_m.x(), float(K.width - 1) - uv.x(), 1e-3f);
    EXPECT_NEAR(uv_m.y(), uv.y(), 1e-3f);
    EXPECT_NEAR(q_m.z(), q.z(), 1e-5f);  // the depth it raycasts is the virtual point's depth
  }
}

TEST(MirrorDepth, RejectsADegeneratePlane) {
  EXPECT_THROW(mirror_camera({100, 100, 32, 24, 64, 48}, Eigen::Isometry3f::Identity(), Eigen::Vector4f(0, 0, 0, 1)),
               std::invalid_argument);
}

}  // namespace
}  // namespace rrg
