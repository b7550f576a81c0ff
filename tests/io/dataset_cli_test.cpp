// `rrg dataset info` through the real executable.
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace rrg::test {
namespace {

TEST(DatasetCli, InfoOnSevenScenesMini) {
  const auto r = run_rrg("dataset info " + (test_data_dir() / "7scenes_mini").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("format:        7scenes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames:        3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("640x480 fx=585.000"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ground truth:  yes (3 of 3 frames)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("(0.067 s)"), std::string::npos) << r.output;
}

TEST(DatasetCli, InfoJson) {
  const auto r = run_rrg("dataset info --json " + (test_data_dir() / "7scenes_mini").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["frames"], 3);
  EXPECT_EQ(j["format"], "7scenes");
  EXPECT_EQ(j["intrinsics"]["width"], 640);
  EXPECT_EQ(j["depth_scale"], 1000.0);
  EXPECT_EQ(j["ground_truth"], true);
  const double valid = j["first_frame"]["valid_depth_fraction"];
  EXPECT_GT(valid, 0.5);
  EXPECT_LE(valid, 1.0);
  EXPECT_GT(j["first_frame"]["depth_min"].get<double>(), 0.0);
  EXPECT_LT(j["first_frame"]["depth_max"].get<double>(), 10.0);
}

TEST(DatasetCli, EmptyFolderAndBadFlagsFail) {
  TempDir dir("io-cli");
  const auto r = run_rrg("dataset info " + dir.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("rrg: error: no dataset found in"), std::string::npos) << r.output;
  const auto bad = run_rrg("dataset info --intrinsics 1,2 " + (test_data_dir() / "7scenes_mini").string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("--intrinsics: invalid intrinsics '1,2'"), std::string::npos) << bad.output;
  const auto usage = run_rrg("dataset info --format kitti " + dir.path().string());  // CLI11 usage error
  EXPECT_NE(usage.exit_code, 0);
  EXPECT_NE(usage.exit_code, 1);
  EXPECT_NE(usage.output.find("--format"), std::string::npos) << usage.output;
}

}  // namespace
}  // namespace rrg::test
