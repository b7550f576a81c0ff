// Camera paths: through the waypoints, constant speed, C1 (no jumps or kinks), always inside the
// room and clear of furniture; novel views close to the path and also in free space.
#include "core/synth/camera_path.h"
#include "core/synth/presets.h"
#include "core/synth/sequence.h"

#include <gtest/gtest.h>

namespace rrg::synth {
namespace {

using Eigen::Vector3d;

double rotation_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / 3.14159265358979;
}

TEST(CameraPath, PassesThroughWaypointsAndIsArcLengthParameterised) {
  const std::vector<Waypoint> w = {{{0, 0, 1}, {0, 5, 1}}, {{2, 0, 1}, {2, 5, 1}}, {{2, 2, 1}, {5, 2, 1}},
                                   {{0, 2, 1}, {-5, 2, 1}}};
  CameraPathParams params;
  params.bob_amplitude = 0.0;
  params.roll_amplitude_deg = 0.0;
  const CameraPath path(w, params);
  // A Catmull-Rom loop around a 2 m square: longer than the square (8 m), shorter than its circle-ish bound.
  EXPECT_GT(path.length(), 8.0);
  EXPECT_LT(path.length(), 8.0 * 1.2);
  EXPECT_TRUE(path.eye_at(0.0).isApprox(w[0].eye, 1e-9));
  EXPECT_TRUE(path.eye_at(path.length()).isApprox(w[0].eye, 1e-9)) << "closed loop";
  EXPECT_NEAR(path.parameter_at(path.length() * 0.25), 1.0, 1e-6) << "symmetric square: a quarter per segment";
  EXPECT_TRUE(path.eye_at(path.length() * 0.5).isApprox(w[2].eye, 1e-6));
  // Uniform speed: equal arc steps give equal chord steps (to second order).
  const double ds = 0.01;
  for (double s = 0.0; s < path.length(); s += 0.137) {
    const double chord = (path.eye_at(s + ds) - path.eye_at(s)).norm();
    EXPECT_NEAR(chord, ds, 1e-5) << "at s=" << s;
  }
  // Pose: camera z looks at the target, camera x is horizontal (no roll), y points down.
  const Eigen::Isometry3d T = path.pose_at(0.0);
  EXPECT_TRUE(T.linear().col(2).isApprox(Vector3d(0, 1, 0), 1e-9));
  EXPECT_NEAR(T.linear().col(0).z(), 0.0, 1e-12);
  EXPECT_LT(T.linear().col(1).z(), 0.0) << "image y is world down";
  EXPECT_NEAR(T.linear().determinant(), 1.0, 1e-12);
  EXPECT_THROW(CameraPath({w[0], w[1]}), std::invalid_argument);
}

TEST(Trajectory, EveryPresetIsSmoothInsideTheRoomAndOutsideFurniture) {
  for (const PresetInfo& info : preset_list()) {
    const SceneSpec spec = make_preset(info.name, 0);
    const CameraPath path = make_camera_path(spec);
    SynthParams params;
    params.preset = info.name;
    params.fps = 30.0;
    params.speed = 0.3;
    params.novel = 25;
    params.frames = int(path.length() / (params.speed / params.fps)) + 40;  // more than one full loop
    const SequencePlan plan = plan_sequence(spec, path, params);
    ASSERT_EQ(plan.frames.size(), size_t(params.frames));
    const double step = params.speed / params.fps;
    double max_step = 0.0, min_step = 1e9, max_accel = 0.0, max_turn = 0.0;
    for (size_t i = 0; i < plan.frames.size(); ++i) {
      const Eigen::Isometry3d& T = plan.frames[i].T_wc;
      EXPECT_NEAR(plan.frames[i].timestamp, double(i) / params.fps, 1e-12);
      ASSERT_TRUE(spec.scene.is_free(T.translation().cast<float>(), 0.15f))
          << info.name << " frame " << i << " at " << T.translation().transpose() << " is inside something";
      if (i == 0) continue;
      const Eigen::Isometry3d& P = plan.frames[i - 1].T_wc;
      const double d = (T.translation() - P.translation()).norm();
      max_step = std::max(max_step, d);
      min_step = std::min(min_step, d);
      max_turn = std::max(max_turn, rotation_deg(P.linear(), T.linear()));
      if (i >= 2) {
        const Vector3d a = T.translation() - 2.0 * P.translation() + plan.frames[i - 2].T_wc.translation();
        max_accel = std::max(max_accel, a.norm());
      }
    }
    std::printf("%s: loop %.2f m, step %.5f..%.5f m, max second difference %.2e m, max turn %.3f deg/frame\n",
                info.name.c_str(), path.length(), min_step, max_step, max_accel, max_turn);
    EXPECT_LT(max_step, step * 1.01) << info.name;
    EXPECT_GT(min_step, step * 0.99) << info.name;
    // C1: the second difference stays at curvature scale (a kink of 10 degrees alone would give 1.7e-3).
    EXPECT_LT(max_accel, 6e-4) << info.name;
    EXPECT_LT(max_turn, 1.0) << info.name << ": degrees per frame";
    // Novel views: near the path, in free space, spread over the recorded stretch.
    ASSERT_EQ(plan.novel.size(), 25u);
    for (size_t k = 0; k < plan.novel.size(); ++k) {
      const Eigen::Isometry3d& N = plan.novel[k].T_wc;
      const Eigen::Isometry3d on_path = path.pose_at(plan.start_offset + params.speed * plan.novel[k].timestamp);
      const double dist = (N.translation() - on_path.translation()).norm();
      EXPECT_LE(dist, 0.061) << info.name << " novel " << k;
      EXPECT_LE(rotation_deg(N.linear(), on_path.linear()), 5.01);
      EXPECT_GT(dist + rotation_deg(N.linear(), on_path.linear()), 1e-4) << "perturbed off the path";
      EXPECT_TRUE(spec.scene.is_free(N.translation().cast<float>(), 0.1f));
      if (k > 0) EXPECT_GT(plan.novel[k].timestamp, plan.novel[k - 1].timestamp);
    }
  }
}

TEST(Trajectory, SeedMovesTheStartAndNothingElseChangesWithIt) {
  const SceneSpec spec = make_preset("office", 0);
  const CameraPath path = make_camera_path(spec);
  SynthParams p;
  p.frames = 10;
  p.novel = 3;
  const SequencePlan a = plan_sequence(spec, path, p);
  const SequencePlan a2 = plan_sequence(spec, path, p);
  p.seed = 5;
  const SequencePlan b = plan_sequence(spec, path, p);
  EXPECT_EQ(a.start_offset, 0.0);
  EXPECT_GT(b.start_offset, 0.0);
  EXPECT_TRUE(a.frames[3].T_wc.isApprox(a2.frames[3].T_wc, 0.0)) << "deterministic";
  EXPECT_FALSE(a.frames[0].T_wc.isApprox(b.frames[0].T_wc, 1e-6));
}

}  // namespace
}  // namespace rrg::synth
