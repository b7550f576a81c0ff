// `rrg fuse` end to end: a synthetic office sequence (rrg synth) fused with its ground-truth poses,
// the mesh scored against the ground-truth mesh with `rrg eval mesh`, and the error paths.
#include "core/tsdf/tsdf_io.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

namespace rrg {
namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

TEST(TsdfCli, FusesASyntheticSequenceIntoAnAccurateMesh) {
  const test::TempDir tmp("tsdf-cli");
  const std::string dir = (tmp / "office").string();
  const auto synth = test::run_rrg("synth --preset office --frames 20 --width 160 --height 120 --out " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const std::string mesh = (tmp / "mesh.ply").string(), vol = (tmp / "v.tsdf").string();
  const auto fuse = test::run_rrg("fuse " + dir + " --out " + mesh + " --voxel 0.02 --device cpu --save " + vol);
  ASSERT_EQ(fuse.exit_code, 0) << fuse.output;
  EXPECT_NE(fuse.output.find("fused 20 frames"), std::string::npos) << fuse.output;
  EXPECT_NE(fuse.output.find("fusion"), std::string::npos) << fuse.output;  // timing summary
  EXPECT_EQ(load_volume(vol, Device::cpu()).version(), 20u);
  EXPECT_EQ(load_volume(vol, Device::cpu()).params().band_sigmas, 3.0f);  // the noise band by default

  // Streaming: with blocks farther than 1 m from the camera moved to host memory after each frame
  // (most of the room), fusion and the slab-wise meshing give the same mesh and volume, byte for byte.
  const std::string mesh_s = (tmp / "mesh_s.ply").string(), vol_s = (tmp / "v_s.tsdf").string();
  const auto streamed = test::run_rrg("fuse " + dir + " --out " + mesh_s + " --voxel 0.02 --device cpu --save " + vol_s +
                                      " --stream-radius 1.0");
  ASSERT_EQ(streamed.exit_code, 0) << streamed.output;
  std::smatch b;
  ASSERT_TRUE(std::regex_search(fuse.output, b, std::regex(R"(into (\d+) blocks)"))) << fuse.output;
  const long blocks = std::stol(b[1]);
  EXPECT_NE(streamed.output.find("into " + b[1].str() + " blocks"), std::string::npos) << streamed.output;
  ASSERT_TRUE(std::regex_search(streamed.output, b, std::regex(R"(at most (\d+) blocks resident, (\d+) in host)")))
      << streamed.output;
  EXPECT_LT(std::stol(b[1]), blocks) << streamed.output;      // never the whole map at once
  EXPECT_GT(std::stol(b[2]), blocks / 2) << streamed.output;  // most of it in host memory at the end
  EXPECT_EQ(file_bytes(mesh_s), file_bytes(mesh));
  EXPECT_EQ(file_bytes(vol_s), file_bytes(vol));

  // Accuracy is measured to samples of the whole-room ground-truth mesh (~120 m^2), so the sample
  // spacing sqrt(A/N) sets a floor: 1M samples give ~1 cm spacing, a mean floor of ~0.5 cm, far
  // below the 2 cm (one voxel) bound. (50k samples would put the floor itself at ~2.5 cm.)
  const auto eval = test::run_rrg("eval mesh --est " + mesh + " --ref " + dir + "/mesh_gt.ply --samples 1000000");
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(eval.output, m, std::regex(R"(accuracy \(cm\)\s+([0-9.]+))"))) << eval.output;
  EXPECT_LT(std::stod(m[1]), 2.0) << eval.output;
}

// Ctrl-C: `rrg fuse` stops before the next frame, still writes the mesh of the frames fused, and
// exits with 128 + SIGINT. (The signal is sent after the 10-frame progress line; 30 frames with a
// raycast each at 5 mm leave seconds before the end.)
TEST(TsdfCli, InterruptedFuseWritesTheMeshOfTheFramesFused) {
  const test::TempDir tmp("tsdf-cli-int");
  const std::string dir = (tmp / "lr").string();
  const auto synth = test::run_rrg("synth --preset living_room --frames 30 --width 160 --height 120 --novel 0 --out " + dir);
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto mesh = tmp / "mesh.ply";
  test::BackgroundRrg rrg("fuse " + dir + " --out " + mesh.string() + " --voxel 0.005 --device cpu --raycast", tmp / "log.txt");
  ASSERT_TRUE(rrg.wait_for_output("fuse: 10 frames fused")) << "rrg fuse did not get to 10 frames";
  rrg.signal(SIGINT);
  EXPECT_EQ(rrg.wait(), 128 + SIGINT);
  std::ifstream log(tmp / "log.txt");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(interrupted after (\d+) frames)"))) << text;
  EXPECT_GE(std::stoi(m[1]), 10);
  EXPECT_LT(std::stoi(m[1]), 30);
  EXPECT_NE(text.find("fused " + m[1].str() + " frames"), std::string::npos) << text;
  EXPECT_TRUE(std::filesystem::exists(mesh));
  EXPECT_GT(std::filesystem::file_size(mesh), 1000u);
}

TEST(TsdfCli, ErrorsExitWithAMessage) {
  const test::TempDir tmp("tsdf-cli");
  const auto missing = test::run_rrg("fuse " + (tmp / "nope").string() + " --out " + (tmp / "m.ply").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("rrg: error:"), std::string::npos) << missing.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "m.ply"));
  const auto usage = test::run_rrg("fuse " + (tmp / "nope").string());  // no --out
  EXPECT_NE(usage.exit_code, 0) << usage.output;  // CLI11's usage error
  EXPECT_NE(usage.output.find("--out is required"), std::string::npos) << usage.output;
  const auto bad_every = test::run_rrg("fuse " + (test::test_data_dir() / "7scenes_mini").string() +
                                       " --out " + (tmp / "m.ply").string() + " --every 0");
  EXPECT_EQ(bad_every.exit_code, 1) << bad_every.output;
  EXPECT_NE(bad_every.output.find("--every"), std::string::npos) << bad_every.output;
  const auto bad_band = test::run_rrg("fuse " + (test::test_data_dir() / "7scenes_mini").string() +
                                      " --out " + (tmp / "m.ply").string() + " --band-sigmas -1");
  EXPECT_NE(bad_band.exit_code, 0) << bad_band.output;
  EXPECT_NE(bad_band.output.find("--band-sigmas"), std::string::npos) << bad_band.output;
  const auto bad_radius = test::run_rrg("fuse " + (test::test_data_dir() / "7scenes_mini").string() +
                                        " --out " + (tmp / "m.ply").string() + " --stream-radius -1");
  EXPECT_NE(bad_radius.exit_code, 0) << bad_radius.output;
  EXPECT_NE(bad_radius.output.find("--stream-radius"), std::string::npos) << bad_radius.output;
  EXPECT_FALSE(std::filesystem::exists(tmp / "m.ply"));
}

TEST(TsdfCli, FusesRealFramesOf7Scenes) {
  const test::TempDir tmp("tsdf-cli");
  const std::string mesh = (tmp / "m.ply").string();
  const auto r = test::run_rrg("fuse " + (test::test_data_dir() / "7scenes_mini").string() + " --out " + mesh +
                               " --voxel 0.02 --device cpu --stream-radius 1.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fused 3 frames"), std::string::npos) << r.output;
  EXPECT_GT(std::filesystem::file_size(mesh), 10000u);
}

}  // namespace
}  // namespace rrg
