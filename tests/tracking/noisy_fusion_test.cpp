// Regression for living_room at 640x480 with depth noise being lost from frame 1 (issue #4): at
// that resolution Kinect-like noise (σ(z) = 1.2 mm + 1.9 mm (z − 0.4)², ≈ 1.4 cm at 3 m) is larger
// than the pixel spacing (≈ 6 mm at 3 m), so normals from central differences of the *raw* depth
// are noise. The TSDF's point-to-plane sdf and grazing-angle test then leave half the model empty
// and ICP's inlier ratio falls under the failure threshold. Fusing with the normals of the
// preprocessed (bilateral-filtered) D_k (Tracker::normal_depth), as `rrg track` and sessions do,
// keeps the model whole. Measured on this scene: raw fusion covers 56 % of the pixels and frame 1 is
// degraded (inlier ratio 0.34); the preprocessed depth covered 95 % and frame 1 was ok (0.73),
// 0.15 mm / 0.006° off. The positions are the sensor's (docs/tracking.md "Positions from the
// sensor, normals from the filter").
#include "core/tracking/se3.h"
#include "core/tracking/tracker.h"
#include "core/tsdf/tsdf_integrate.h"
#include "tests/tracking/box_scene.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace rrg {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The synthetic generator's sensor model (core/synth/depth_noise.h), drawn from a fixed seed.
DepthImage add_kinect_noise(DepthImage depth, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, 1.0f);
  for (float& z : depth.pixels())
    if (z > 0.0f) z += (0.0012f + 0.0019f * (z - 0.4f) * (z - 0.4f)) * g(rng);
  return depth;
}

struct NoisyTwoFrames {
  Intrinsics K{512.0f, 512.0f, 319.5f, 239.5f, 640, 480};  // the synth presets' 640x480 camera
  // Towards a corner of the 4 m box: mean depth 2.6 m (living_room's range), σ ≈ 1-2 cm.
  Eigen::Isometry3f T0 = test::look_at({-0.5f, -0.4f, -0.3f}, {2.0f, 1.0f, 0.8f});
  Eigen::Isometry3f T1;
  DepthImage d0, d1;
  ColorImage color{640, 480, Eigen::Vector3f(0.5f, 0.5f, 0.5f)};
  NoisyTwoFrames() {
    Eigen::Isometry3f delta = Eigen::Isometry3f::Identity();  // one frame of hand-held motion
    delta.rotate(Eigen::AngleAxisf(float(0.5 * kDeg), Eigen::Vector3f(0.2f, 1.0f, 0.1f).normalized()));
    delta.translation() = Eigen::Vector3f(0.008f, -0.004f, 0.006f);
    T1 = T0 * delta;
    d0 = add_kinect_noise(test::render_box(K, T0).depth, 1);
    d1 = add_kinect_noise(test::render_box(K, T1).depth, 2);
  }
};

TEST(NoisyFusion, TracksSecondFrameAt640x480WhenFusingWithFilteredNormals) {
  const NoisyTwoFrames s;
  TsdfParams tsdf;  // rrg track's defaults: 1 cm voxels, truncation 4 voxels
  tsdf.voxel_size = 0.01f;
  tsdf.truncation = 0.04f;
  tsdf.max_depth = 5.0f;
  TsdfVolume volume(tsdf, Device::cpu());
  TsdfModelSource model(volume, s.K);
  TrackingParams params;
  params.mode = TrackingMode::Icp;
  Tracker tracker(params, s.K, Device::cpu());
  tracker.set_initial_pose(s.T0);

  const TrackResult r0 = tracker.track({0, &s.color, &s.d0, nullptr}, model, nullptr);
  ASSERT_TRUE(r0.first);
  ASSERT_NE(tracker.normal_depth(), nullptr);
  integrate(volume, DeviceImage<float>::from_host(s.d0, Device::cpu()),
            DeviceImage<Color>::from_host(s.color, Device::cpu()), s.K, s.T0, nullptr, tracker.normal_depth());
  model.invalidate();

  // The model seen from T0 covers most pixels that have depth, and frame 1 tracks. Measured: with
  // the filtered normals 81 % of the pixels, inlier ratio 0.455, 0.20 mm / 0.006° off; with the raw
  // depth's own normals 60 %, 0.357, 0.54 mm / 0.012°. (Fusing the filtered depth itself covered 95 %
  // at 0.73, but its positions drift with the view: ScaleDrift.) One frame of raw depth is a rough
  // surface at this noise; later frames average it.
  const IcpModel m = model.model_at(s.T0);
  const auto normals = m.normals->to_host();
  size_t covered = 0;
  for (const auto& n : normals.pixels()) covered += n.squaredNorm() > 0.5f;
  EXPECT_GT(double(covered), 0.7 * double(normals.pixels().size())) << covered << " model pixels";

  const TrackResult r1 = tracker.track({1, &s.color, &s.d1, nullptr}, model, nullptr);
  EXPECT_NE(r1.state, TrackingState::Lost) << r1.note << " inlier ratio " << r1.icp.inlier_ratio;
  EXPECT_GT(r1.icp.inlier_ratio, 0.4);
  EXPECT_LT(translation_distance(r1.T_wc.cast<double>(), s.T1.cast<double>()), 0.003);
  EXPECT_LT(rotation_distance(r1.T_wc.cast<double>(), s.T1.cast<double>()), 0.2 * kDeg);
}

// A room seen from its far side (office, synth seed 23, was lost from frame 1 on): at 3.5–4.5 m a
// Kinect v1's σ_n is 2–3 cm over a 1.5 cm pixel footprint at 320x240, so the normals of a correct
// pose differ by more than the solver's 30° on most pairs. The state's measure counts the pairs
// the noise explains instead (IcpParams::min_agreement); with the solver's inlier ratio the frame
// was lost.
TEST(NoisyFusion, ARoomSeenFromItsFarSideTracks) {
  const Intrinsics K{256.0f, 256.0f, 159.5f, 119.5f, 320, 240};  // the synth presets' 320x240 camera
  const Eigen::Isometry3f T0 = test::look_at({-1.7f, -1.5f, -0.9f}, {2.0f, 1.6f, 0.9f});
  Eigen::Isometry3f delta = Eigen::Isometry3f::Identity();
  delta.rotate(Eigen::AngleAxisf(float(0.4 * kDeg), Eigen::Vector3f(0.1f, 1.0f, 0.2f).normalized()));
  delta.translation() = Eigen::Vector3f(0.006f, -0.003f, 0.008f);
  const Eigen::Isometry3f T1 = T0 * delta;
  const DepthImage d0 = add_kinect_noise(test::render_box(K, T0).depth, 3);
  const DepthImage d1 = add_kinect_noise(test::render_box(K, T1).depth, 4);
  double mean_depth = 0;
  size_t n = 0;
  for (float z : d0.pixels())
    if (z > 0) mean_depth += z, ++n;
  mean_depth /= double(n);
  ASSERT_GT(mean_depth, 3.5) << "the scene is meant to be far";
  const ColorImage color(320, 240, Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  TsdfParams tsdf;
  tsdf.voxel_size = 0.01f;
  tsdf.truncation = 0.04f;
  TsdfVolume volume(tsdf, Device::cpu());
  TsdfModelSource model(volume, K);
  TrackingParams params;
  params.mode = TrackingMode::Icp;
  Tracker tracker(params, K, Device::cpu());
  tracker.set_initial_pose(T0);
  ASSERT_TRUE(tracker.track({0, &color, &d0, nullptr}, model, nullptr).first);
  integrate(volume, DeviceImage<float>::from_host(d0, Device::cpu()), DeviceImage<Color>::from_host(color, Device::cpu()),
            K, T0, nullptr, tracker.normal_depth());
  model.invalidate();
  const TrackResult r1 = tracker.track({1, &color, &d1, nullptr}, model, nullptr);
  std::printf("[ far room: mean depth %.2f m, agreement %.3f, solver inlier ratio %.3f, %.2f mm / %.3f deg off ]\n",
              mean_depth, r1.icp.agreement, r1.icp.inlier_ratio,
              1e3 * translation_distance(r1.T_wc.cast<double>(), T1.cast<double>()),
              rotation_distance(r1.T_wc.cast<double>(), T1.cast<double>()) / kDeg);
  EXPECT_EQ(r1.state, TrackingState::Ok) << r1.note;
  EXPECT_GT(r1.icp.agreement, params.icp.ok_agreement);
  EXPECT_LT(r1.icp.inlier_ratio, params.icp.min_agreement) << "the solver's inliers no longer show the failure";
  EXPECT_LT(translation_distance(r1.T_wc.cast<double>(), T1.cast<double>()), 0.005);
  EXPECT_LT(rotation_distance(r1.T_wc.cast<double>(), T1.cast<double>()), 0.2 * kDeg);
}

}  // namespace
}  // namespace rrg
