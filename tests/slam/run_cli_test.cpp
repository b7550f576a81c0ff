// `rrg run` through the real executable on a short synthetic sequence: the files it promises and
// the metrics in metrics.json, including completion over the observed part of the ground truth.
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace rrg {
namespace {

TEST(RunCli, WritesOutputsAndScoresGeometryOnTheObservedSurface) {
  test::TempDir dir("run_cli");
  const auto seq = dir / "seq";
  auto r = test::run_rrg("synth --preset living_room --frames 20 --width 160 --height 120 --novel 2 --noise --out " +
                         seq.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto out = dir / "run";
  r = test::run_rrg("run --dataset " + seq.string() + " --out " + out.string() +
                    " --device cpu --sync --gt-poses --no-progress --set tsdf.voxel_size=0.02 --set tsdf.truncation=0.08");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"trajectory.txt", "mesh.ply", "mesh.drc", "metrics.json", "timings.json", "config.yaml"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;

  const auto j = nlohmann::json::parse(std::ifstream(out / "metrics.json"));
  ASSERT_TRUE(j.contains("geometry")) << j.dump(2);
  const auto& g = j["geometry"];
  // 20 frames of a camera path see part of the room: the rest of the ground-truth mesh (other
  // walls, the far side of furniture) is not observed and must not count against completion.
  const double observed = g.at("observed_fraction").get<double>();
  EXPECT_GT(observed, 0.05);
  EXPECT_LT(observed, 0.95);
  const double comp = g.at("completion_cm").get<double>(), whole = g.at("completion_whole_mesh_cm").get<double>();
  EXPECT_LT(comp, 0.5 * whole) << j.dump(2);
  // Ground-truth poses and 2 cm voxels: the observed surface is reconstructed to about a voxel.
  EXPECT_LT(comp, 3.0) << j.dump(2);
  EXPECT_LT(g.at("accuracy_cm").get<double>(), 3.0) << j.dump(2);
  EXPECT_GT(g.at("completion_ratio_3cm").get<double>(), 0.8) << j.dump(2);
}

}  // namespace
}  // namespace rrg
