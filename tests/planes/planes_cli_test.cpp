// `rrg planes` through the real executable on a tiny synthetic sequence.
#include "core/planes/plane_eval.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

namespace rrg {
namespace {

class PlanesCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir("planes_cli");
    const auto r = test::run_rrg("synth --preset living_room --frames 3 --width 160 --height 120 --novel 0 --out " +
                                 (dir_->path() / "seq").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() {
    delete dir_;  // NOLINT: suite-wide scratch folder
    dir_ = nullptr;
  }
  static std::string seq() { return (dir_->path() / "seq").string(); }
  static test::TempDir* dir_;
};
test::TempDir* PlanesCli::dir_ = nullptr;

std::string json_part(const std::string& output) {
  const auto a = output.find('{');
  const auto b = output.rfind('}');
  return a == std::string::npos ? "{}" : output.substr(a, b - a + 1);
}

TEST_F(PlanesCli, SegmentPrintsScoresAndWritesMaps) {
  const auto out = dir_->path() / "maps";
  const auto r = test::run_rrg("planes segment --dataset " + seq() + " --json --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(json_part(r.output));
  EXPECT_EQ(j["frames"].size(), 3u);
  EXPECT_GT(j["frames"][0]["planes"].size(), 2u);  // a room: floor, walls, furniture
  EXPECT_GT(j["precision"].get<double>(), 0.5);
  EXPECT_GT(j["recall"].get<double>(), 0.5);
  EXPECT_TRUE(std::filesystem::exists(out / "000002.png"));
}

// The stop hook (Ctrl-C in `rrg planes eval`): polled after each frame; the report covers the
// frames done and says it was interrupted.
TEST_F(PlanesCli, EvalStopsWhenAskedAndScoresTheFramesDone) {
  PlaneEvalOptions e;
  e.dataset = seq();
  e.period = 1;
  e.voxel_size = 0.04f;
  int polls = 0;
  e.stop = [&polls] { return ++polls >= 2; };  // after the second frame
  const PlaneEvalReport r = run_plane_eval(e);
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.frames, 2u);
  EXPECT_EQ(r.windows, 2u);
  EXPECT_EQ(polls, 2);
  e.stop = [] { return false; };
  const PlaneEvalReport all = run_plane_eval(e);
  EXPECT_FALSE(all.interrupted);
  EXPECT_EQ(all.frames, 3u);
}

TEST_F(PlanesCli, EvalRunsBothCuesWithFusion) {
  const auto r = test::run_rrg("planes eval --dataset " + seq() + " --semantics none,labels --period 1 --voxel 0.04 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(json_part(r.output));
  EXPECT_EQ(j["frames"].get<int>(), 3);
  EXPECT_EQ(j["windows"].get<int>(), 3);
  ASSERT_EQ(j["cues"].size(), 2u);
  EXPECT_EQ(j["cues"][0]["semantics"], "none");
  EXPECT_EQ(j["cues"][1]["semantics"], "labels");
  EXPECT_GT(j["global_planes"].get<int>(), 2);
  // Three windows are fewer than the four reflective votes L_ref needs.
  EXPECT_EQ(j["cues"][1]["accepted"].get<int>(), 0);
  // The variance the input shows on the reflective GT planes it saw: the glossy floor among them,
  // with its points and a fraction in [0, 1]; recall over the verifiable ones beside the plain one.
  ASSERT_TRUE(j["observed_variance"].is_array());
  bool floor = false;
  for (const auto& o : j["observed_variance"]) {
    EXPECT_GT(o["points"].get<int64_t>(), 0);
    EXPECT_GE(o["fraction_above"].get<double>(), 0.0);
    EXPECT_LE(o["fraction_above"].get<double>(), 1.0);
    EXPECT_EQ(o["verifiable"].get<bool>(), o["fraction_above"].get<double>() > 0.05);
    floor = floor || o["name"] == "floor";
  }
  EXPECT_TRUE(floor) << j["observed_variance"].dump();
  EXPECT_LE(j["cues"][0]["gt_verifiable"].get<int>(), j["cues"][0]["gt_reflective"].get<int>());
  EXPECT_TRUE(j["cues"][0].contains("verifiable_recall"));
}

// A sensor that loses the mirror (`rrg synth --mirror-depth invalid`): the labels cue's mirror mask
// is filled from the wall around it (planes.fill) unless --no-fill.
TEST_F(PlanesCli, EvalFillsTheDepthOfALostMirror) {
  const std::string lost = (dir_->path() / "lost").string();
  auto r = test::run_rrg("synth --preset mirror_room --frames 3 --width 160 --height 120 --novel 0 --mirror-depth invalid --out " +
                         lost);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_rrg("planes eval --dataset " + lost + " --semantics labels --period 1 --voxel 0.04 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto filled = nlohmann::json::parse(json_part(r.output));
  // the glass is about a tenth of each frame here
  EXPECT_GT(filled["filled_pixels"].get<int64_t>(), 3 * 160 * 120 / 20);
  r = test::run_rrg("planes eval --dataset " + lost + " --semantics labels --period 1 --voxel 0.04 --json --no-fill");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto unfilled = nlohmann::json::parse(json_part(r.output));
  EXPECT_EQ(unfilled["filled_pixels"].get<int64_t>(), 0);
  // The filled glass is a plane segmentation finds (here recall 1.00 against 0.75 without the fill).
  EXPECT_GT(filled["segmentation"]["recall"].get<double>(), unfilled["segmentation"]["recall"].get<double>());
  EXPECT_GT(filled["global_planes"].get<int>(), unfilled["global_planes"].get<int>());
}

TEST_F(PlanesCli, ErrorsAndUsage) {
  auto r = test::run_rrg("planes eval --dataset " + seq() + " --semantics magic");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("unknown semantics 'magic'"), std::string::npos) << r.output;
  r = test::run_rrg("planes segment --dataset " + (dir_->path() / "nothing").string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("rrg: error:"), std::string::npos);
  r = test::run_rrg("planes segment");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = test::run_rrg("planes eval --dataset " + seq() + " --semantics remote");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no segmenter address"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rrg
