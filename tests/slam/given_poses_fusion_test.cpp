// With given poses (SessionConfig::gt_poses, `rrg run --gt-poses`) no tracker preprocesses the
// frame, yet the session must fuse it as a tracked session does: the sensor's depth for positions
// and the bilateral-filtered depth for the normals of the point-to-plane sdf and the grazing test
// (Tracker::normal_depth(), docs/tracking.md "Positions from the sensor, normals from the filter").
// Otherwise the mapping-only ablation changes fusion as well as the poses. One noisy 640x480
// living_room frame, where the raw depth's normals are noise (tests/tracking/noisy_fusion_test.cpp).
#include "core/io/dataset.h"
#include "core/slam/session.h"
#include "core/tracking/preprocess.h"
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

namespace rrg {
namespace {

std::vector<std::array<float, 3>> sorted_positions(const TriangleMesh& mesh) {
  std::vector<std::array<float, 3>> p;
  p.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) p.push_back({v.x(), v.y(), v.z()});
  std::sort(p.begin(), p.end());
  return p;
}

TEST(GivenPosesFusion, NormalsComeFromTheFilteredDepthAsWhenTracked) {
  const test::TempDir dir("given_poses");
  const auto seq = dir.path() / "seq";
  const auto r = test::run_rrg("synth --preset living_room --frames 1 --width 640 --height 480 --noise --out " +
                               seq.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto dataset = io::open_dataset(seq);
  const io::Frame f = dataset->load(0);
  ASSERT_TRUE(f.T_wc_gt);
  const Eigen::Isometry3f T_wc = f.T_wc_gt->cast<float>();

  auto session_mesh = [&](bool bilateral) {
    SessionConfig c;
    c.K = dataset->intrinsics();
    c.tsdf.voxel_size = 0.01f;
    c.tsdf.truncation = 0.04f;
    c.gt_poses = true;
    c.semantics = "none";  // no reflective fill: the frame's depth goes to fusion as it is
    c.sync = true;
    c.mapping.iterations = 1;
    c.tracking.preprocess.bilateral = bilateral;
    Session s(c);
    s.process({0, 0.0, f.color, f.depth, std::nullopt, T_wc});
    s.finish();
    return std::pair{s.mesh(), c.tsdf_params()};
  };
  // The reference: the same frame fused directly, positions from its depth, normals from its filter.
  auto direct_mesh = [&](const TsdfParams& params, bool filtered) {
    TsdfVolume volume(params, Device::cpu());
    const auto depth = DeviceImage<float>::from_host(f.depth, Device::cpu());
    DeviceImage<float> normal_depth;
    if (filtered) EXPECT_TRUE(filter_depth_into(normal_depth, depth, PreprocessParams{}));
    integrate(volume, depth, DeviceImage<Color>::from_host(f.color, Device::cpu()), dataset->intrinsics(), T_wc,
              nullptr, filtered ? &normal_depth : nullptr);
    return extract_mesh(volume);
  };

  const auto [filtered, params] = session_mesh(true);
  const auto filtered_positions = sorted_positions(filtered);
  ASSERT_GT(filtered_positions.size(), 1000u);
  EXPECT_EQ(filtered_positions, sorted_positions(direct_mesh(params, true)));
  // The filter's normals are not the raw depth's, so this frame's mesh tells them apart; with the
  // filter off the session takes the depth's own normals.
  const auto raw_positions = sorted_positions(direct_mesh(params, false));
  EXPECT_NE(filtered_positions, raw_positions);
  EXPECT_EQ(sorted_positions(session_mesh(false).first), raw_positions);
}

}  // namespace
}  // namespace rrg
