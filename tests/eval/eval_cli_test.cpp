// `rrg eval ate|images|mesh` through the real executable: tables, JSON, exit codes, error messages.
#include "core/io/image_io.h"
#include "core/io/ply.h"
#include "core/io/trajectory.h"
#include "tests/eval/eval_test_util.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace rrg::eval {
namespace {

using rrg::test::run_rrg;
using rrg::test::TempDir;

// The value printed after `label` on its table row "  <label>  <value>" ("" when there is none).
std::string table_value(const std::string& output, const std::string& label) {
  std::istringstream in(output);
  const std::string prefix = "  " + label + " ";
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) != 0) continue;
    std::istringstream rest(line.substr(prefix.size()));
    std::string value;
    rest >> value;
    return value;
  }
  return "";
}

std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

TEST(EvalCli, AteOfATrajectoryAgainstItselfPrintsZero) {
  TempDir dir("eval-cli");
  io::write_tum_trajectory(dir / "traj.txt", test::smooth_trajectory(120));
  const auto r = run_rrg("eval ate --est " + q(dir / "traj.txt") + " --ref " + q(dir / "traj.txt"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(table_value(r.output, "matched poses"), "120") << r.output;
  EXPECT_EQ(table_value(r.output, "ATE RMSE aligned (cm)"), "0.00") << r.output;
  EXPECT_EQ(table_value(r.output, "ATE RMSE unaligned (cm)"), "0.00") << r.output;
  EXPECT_EQ(table_value(r.output, "RPE trans RMSE (cm/s)"), "0.00") << r.output;
  EXPECT_NE(r.output.find("rigid SE(3) Umeyama, no scale"), std::string::npos) << r.output;
}

TEST(EvalCli, AteJsonHasTheFieldsAndTheDrift) {
  TempDir dir("eval-cli");
  const io::Trajectory ref = test::smooth_trajectory(120);
  io::Trajectory est = ref;
  for (auto& p : est) p.T_wc.translation() += Eigen::Vector3d(0.05, 0, 0) * (p.timestamp - ref.front().timestamp);
  io::write_tum_trajectory(dir / "ref.txt", ref);
  io::write_tum_trajectory(dir / "est.txt", est);
  const auto r = run_rrg("eval ate --json --est " + q(dir / "est.txt") + " --ref " + q(dir / "ref.txt"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);  // stdout holds nothing but the JSON
  EXPECT_EQ(j.at("matched"), 120);
  EXPECT_EQ(j.at("alignment"), "rigid");
  for (const char* k : {"rmse", "mean", "median", "max", "rmse_unaligned"}) EXPECT_TRUE(j.at("ate_cm").contains(k)) << k;
  EXPECT_GT(j.at("ate_cm").at("rmse").get<double>(), 0.1);
  EXPECT_EQ(j.at("rpe").at("pairs"), 90);
  EXPECT_NEAR(j.at("rpe").at("trans_rmse_cm").get<double>(), 5.0, 1e-4);  // 5 cm/s, written at 1e-9 m
  EXPECT_NEAR(j.at("rpe").at("rot_rmse_deg").get<double>(), 0.0, 1e-4);
}

TEST(EvalCli, AteErrorsNameTheFiles) {
  TempDir dir("eval-cli");
  io::write_tum_trajectory(dir / "ref.txt", test::smooth_trajectory(50));
  auto r = run_rrg("eval ate --est " + q(dir / "nope.txt") + " --ref " + q(dir / "ref.txt"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("rrg: error:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("nope.txt"), std::string::npos) << r.output;

  io::Trajectory late = test::smooth_trajectory(50, 30.0, 5000.0);  // no stamp within 0.02 s
  io::write_tum_trajectory(dir / "late.txt", late);
  r = run_rrg("eval ate --est " + q(dir / "late.txt") + " --ref " + q(dir / "ref.txt"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("late.txt"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ref.txt"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("only 0 of 50"), std::string::npos) << r.output;

  r = run_rrg("eval ate --est " + q(dir / "ref.txt") + " --ref " + q(dir / "ref.txt") + " --max-dt -1");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.exit_code, 1) << "a bad flag is a usage error, not a runtime failure: " << r.output;
}

TEST(EvalCli, ImagesOnTwoFolders) {
  TempDir dir("eval-cli");
  // Pair a: 8-bit 51 vs 77 → 19.83 dB; pair b identical → inf; the mean is inf, JSON null.
  io::write_color_png(dir / "est/a.png", ColorImage(12, 10, Color::Constant(51.0f / 255.0f)));
  io::write_color_png(dir / "ref/a.png", ColorImage(12, 10, Color::Constant(77.0f / 255.0f)));
  io::write_color_png(dir / "est/b.png", ColorImage(12, 10, Color(0.2f, 0.4f, 0.6f)));
  io::write_color_png(dir / "ref/b.png", ColorImage(12, 10, Color(0.2f, 0.4f, 0.6f)));
  auto r = run_rrg("eval images --per-image --est " + q(dir / "est") + " --ref " + q(dir / "ref"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(table_value(r.output, "images"), "2") << r.output;
  EXPECT_EQ(table_value(r.output, "mean PSNR (dB)"), "inf") << r.output;
  EXPECT_EQ(table_value(r.output, "a"), "19.83") << r.output;

  r = run_rrg("eval images --json --per-image --est " + q(dir / "est") + " --ref " + q(dir / "ref"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j.at("count"), 2);
  EXPECT_TRUE(j.at("psnr_db").is_null());
  ASSERT_EQ(j.at("images").size(), 2u);
  EXPECT_NEAR(j.at("images")[0].at("psnr_db").get<double>(), -20.0 * std::log10(26.0 / 255.0), 1e-4);
  EXPECT_NEAR(j.at("images")[1].at("ssim").get<double>(), 1.0, 1e-12);

  io::write_color_png(dir / "ref/c.png", ColorImage(12, 10));
  r = run_rrg("eval images --est " + q(dir / "est") + " --ref " + q(dir / "ref"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("c.png"), std::string::npos) << r.output;
}

TEST(EvalCli, MeshOfTwoParallelSquaresPrintsTwoCentimetres) {
  TempDir dir("eval-cli");
  io::write_ply_mesh(dir / "est.ply", test::square(0, 0, 0.5, 0.5, 0.02));
  io::write_ply_mesh(dir / "gt.ply", test::square(0, 0, 0.5, 0.5, 0.0));
  auto r = run_rrg("eval mesh --est " + q(dir / "est.ply") + " --ref " + q(dir / "gt.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(table_value(r.output, "accuracy (cm)"), "2.00") << r.output;
  EXPECT_EQ(table_value(r.output, "completion (cm)"), "2.00") << r.output;
  EXPECT_EQ(table_value(r.output, "completion ratio (< 3 cm, %)"), "100.00") << r.output;

  r = run_rrg("eval mesh --json --samples 20000 --threshold 0.01 --est " + q(dir / "est.ply") + " --ref " +
              q(dir / "gt.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j.at("est_samples"), 20000);
  EXPECT_EQ(j.at("threshold_m"), 0.01);
  EXPECT_NEAR(j.at("accuracy_cm").get<double>(), 2.0, 0.02);
  EXPECT_EQ(j.at("completion_ratio"), 0.0);  // 2 cm > τ = 1 cm
  EXPECT_EQ(j.at("accuracy_ratio"), 0.0);

  r = run_rrg("eval mesh --est " + q(dir / "missing.ply") + " --ref " + q(dir / "gt.ply"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("missing.ply"), std::string::npos) << r.output;
}

// `--observed-by`: one frame (identity pose, flat depth of 2 m over 40x30 px) sees the front of a
// 1 m² panel 2 cm thick; the reference also holds the panel's back and a square out of view, each
// 1 m². The estimate is the front alone: completion over what the frame observed is the sampling
// floor, over the whole reference it is not.
TEST(EvalCli, MeshObservedByADatasetScoresTheSurfaceItsFramesSaw) {
  TempDir dir("eval-cli");
  const std::filesystem::path seq = dir / "seq";
  std::filesystem::create_directories(seq);
  std::ofstream(seq / "rgb.txt") << "# timestamp filename\n0.000000 rgb/000000.png\n";
  std::ofstream(seq / "depth.txt") << "# timestamp filename\n0.000000 depth/000000.png\n";
  std::ofstream(seq / "groundtruth.txt") << "# timestamp tx ty tz qx qy qz qw\n0.000000 0 0 0 0 0 0 1\n";
  std::ofstream(seq / "camera.json") << R"({"width":40,"height":30,"fx":20,"fy":20,"cx":19.5,"cy":14.5,"depth_scale":5000})";
  io::write_color_png(seq / "rgb/000000.png", ColorImage(40, 30, Color(0.5f, 0.5f, 0.5f)));
  io::write_depth_png(seq / "depth/000000.png", DepthImage(40, 30, 2.0f), 5000.0f);
  const auto flipped = [](TriangleMesh m) {  // the other winding: normal −z, towards the camera
    for (auto& f : m.triangles) std::swap(f[1], f[2]);
    return m;
  };
  const TriangleMesh front = flipped(test::square(-0.5, -0.5, 1, 1, 2.0));
  const TriangleMesh back = test::square(-0.5, -0.5, 1, 1, 2.02), away = flipped(test::square(10, 0, 1, 1, 2.0));
  TriangleMesh ref;
  for (const TriangleMesh* m : {&front, &back, &away}) {
    const int base = int(ref.vertices.size());
    ref.vertices.insert(ref.vertices.end(), m->vertices.begin(), m->vertices.end());
    for (const auto& f : m->triangles) ref.triangles.push_back(f + Eigen::Vector3i::Constant(base));
  }
  io::write_ply_mesh(dir / "est.ply", front);
  io::write_ply_mesh(dir / "gt.ply", ref);
  const std::string cmd = "eval mesh --json --est " + q(dir / "est.ply") + " --ref " + q(dir / "gt.ply");
  auto r = run_rrg(cmd + " --observed-by " + q(seq));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto j = nlohmann::json::parse(r.output);
  EXPECT_NEAR(j.at("observed_fraction").get<double>(), 1.0 / 3.0, 0.01);  // the front only, not its back
  EXPECT_LT(j.at("completion_cm").get<double>(), 0.3);
  EXPECT_EQ(j.at("completion_ratio"), 1.0);
  EXPECT_GT(j.at("completion_whole_mesh_cm").get<double>(), 100.0);  // the out-of-view square, ~10 m away
  r = run_rrg(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  j = nlohmann::json::parse(r.output);
  EXPECT_GT(j.at("completion_cm").get<double>(), 100.0);
  EXPECT_FALSE(j.contains("observed_fraction"));

  r = run_rrg("eval mesh --est " + q(dir / "est.ply") + " --ref " + q(dir / "gt.ply") + " --observed-by " +
              q(dir / "nowhere"));
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("nowhere"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rrg::eval
