// `rrg run` through the real executable on a short synthetic sequence: the files it promises and
// the metrics in metrics.json, including completion over the observed part of the ground truth.
#include "core/io/synth_layout.h"
#include "core/planes/plane_metrics.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace rrg {
namespace {

// A 160x120 `rrg synth` sequence in dir/seq (empty path when synth failed; the failure is reported).
std::filesystem::path synth(const test::TempDir& dir, const std::string& preset, int frames, int novel,
                            const std::string& extra = "") {
  const auto seq = dir / "seq";
  const auto r = test::run_rrg("synth --preset " + preset + " --frames " + std::to_string(frames) +
                               " --width 160 --height 120 --novel " + std::to_string(novel) + extra + " --out " +
                               seq.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? seq : std::filesystem::path();
}

// Frames are decoded ahead on loader threads; a frame that cannot be read must still stop the run
// at that frame, with an error naming the file, after the frames before it were processed.
TEST(RunCli, AnUnreadableFrameStopsTheRunAndNamesTheFile) {
  test::TempDir dir("run_cli_bad");
  const auto seq = synth(dir, "living_room", 12, 1);
  ASSERT_FALSE(seq.empty());
  const auto bad = seq / "depth" / "000007.png";
  ASSERT_TRUE(std::filesystem::exists(bad));
  std::ofstream(bad, std::ios::trunc) << "not a png";
  auto r = test::run_rrg("-v run --dataset " + seq.string() + " --out " + (dir / "run").string() +
                         " --device cpu --sync --gt-poses --no-progress --set tsdf.voxel_size=0.02 --set tsdf.truncation=0.08");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("000007.png"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "metrics.json")) << "no metrics for a run that did not finish";
}

TEST(RunCli, WritesOutputsAndScoresGeometryOnTheObservedSurface) {
  test::TempDir dir("run_cli");
  const auto seq = synth(dir, "living_room", 20, 2, " --noise");
  ASSERT_FALSE(seq.empty());
  const auto out = dir / "run";
  auto r = test::run_rrg("run --dataset " + seq.string() + " --out " + out.string() +
                         " --device cpu --sync --gt-poses --no-progress --set tsdf.voxel_size=0.02 --set tsdf.truncation=0.08");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"trajectory.txt", "mesh.ply", "mesh.drc", "metrics.json", "timings.json", "config.yaml"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;

  // The mapping step's stages are reported, and they are parts of the step.
  const auto t = nlohmann::json::parse(std::ifstream(out / "timings.json"));
  ASSERT_GT(t.at("mapping_steps").get<int>(), 0) << t.dump(2);
  EXPECT_EQ(t.at("schedule").get<std::string>(), "sync");
  EXPECT_EQ(t.at("mapping_waits").get<int>(), 0);  // inline steps never wait for another
  // Every sync step runs mapping.iterations (only live steps scale them).
  EXPECT_EQ(t.at("mapping_iterations").get<int64_t>(), t.at("mapping_steps").get<int64_t>() * 30) << t.dump(2);
  double stages = 0;
  for (const char* k : {"mapping_raycast_per_step", "mapping_densify_per_step", "mapping_optimise_per_step",
                        "mapping_prune_per_step"}) {
    ASSERT_TRUE(t.contains(k)) << k;
    EXPECT_GE(t.at(k).get<double>(), 0.0) << k;
    stages += t.at(k).get<double>();
  }
  EXPECT_GT(t.at("mapping_optimise_per_step").get<double>(), 0.0) << t.dump(2);
  EXPECT_LE(stages, t.at("mapping_step_per_step").get<double>() * 1.0001 + 1e-6) << t.dump(2);
  EXPECT_NE(r.output.find("optimise"), std::string::npos) << r.output;
  // The optimisation's parts: each ran, and together they are most of it (the rest: choosing
  // the frame, the loop itself).
  double parts = 0;
  for (const char* k : {"mapping_optimise_render_per_step", "mapping_optimise_loss_per_step",
                        "mapping_optimise_backward_per_step", "mapping_optimise_adam_per_step"}) {
    ASSERT_TRUE(t.contains(k)) << k;
    EXPECT_GT(t.at(k).get<double>(), 0.0) << k;
    parts += t.at(k).get<double>();
  }
  EXPECT_LE(parts, t.at("mapping_optimise_per_step").get<double>() * 1.0001 + 1e-6) << t.dump(2);
  EXPECT_GE(parts, t.at("mapping_optimise_per_step").get<double>() * 0.9) << t.dump(2);
  EXPECT_NE(r.output.find("backward"), std::string::npos) << r.output;
  // The tracking mask's part of the ORB stage.
  ASSERT_TRUE(t.contains("orb_mask"));
  EXPECT_LE(t.at("orb_mask").get<double>(), t.at("orb").get<double>() * 1.0001 + 1e-6) << t.dump(2);

  const auto j = nlohmann::json::parse(std::ifstream(out / "metrics.json"));
  // The sensor kept every reflective surface of living_room (floor, TV, table): nothing filled.
  ASSERT_TRUE(j.contains("reflective_fill")) << j.dump(2);
  EXPECT_EQ(j["reflective_fill"]["frames"].get<int64_t>(), 0);
  EXPECT_EQ(j["reflective_fill"]["pixels"].get<int64_t>(), 0);
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

  // Held-out PSNR per ground-truth reflective plane: one entry per reflective plane of planes.json
  // that a novel view sees, over exactly that plane's pixels in novel/planes/.
  const auto gt_planes = read_gt_planes(seq / "planes.json");
  std::map<int, size_t> seen;
  for (size_t i = 0; i < 2; ++i) {
    const LabelImage ids = io::read_synth_planes(seq / "novel", i);
    for (size_t k = 0; k < ids.size(); ++k)
      if (gt_planes.count(int(ids[k])) && gt_planes.at(int(ids[k])).reflective) ++seen[int(ids[k])];
  }
  ASSERT_FALSE(seen.empty()) << "the novel views should see the floor";
  const auto& per_plane = j.at("held_out").at("reflective_planes");
  ASSERT_EQ(per_plane.size(), seen.size()) << per_plane.dump(2);
  for (const auto& e : per_plane) {
    const int id = e.at("id").get<int>();
    ASSERT_TRUE(seen.count(id)) << id;
    EXPECT_EQ(e.at("pixels").get<size_t>(), seen.at(id));
    EXPECT_EQ(e.at("name").get<std::string>(), gt_planes.at(id).name);
    EXPECT_GT(e.at("psnr_db").get<double>(), 5.0);
    EXPECT_LT(e.at("psnr_db").get<double>(), 60.0);
  }
}

// --live and --sync exclude each other: refused before any work, naming both.
TEST(RunCli, LiveAndSyncAreRefusedTogether) {
  test::TempDir dir("run_cli_excl");
  const auto seq = synth(dir, "office", 2, 0);
  ASSERT_FALSE(seq.empty());
  const auto out = dir / "run";
  auto r = test::run_rrg("run --dataset " + seq.string() + " --out " + out.string() + " --live --sync --no-progress");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--live"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--sync"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The same through the config (a YAML file or --set): the session's validation names both.
  r = test::run_rrg("run --dataset " + seq.string() + " --out " + out.string() + " --sync --set live=true --no-progress");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("sync and live"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

// --rate feeds frame i no earlier than i / rate after the start, as a sensor streams: 6 frames at
// 20 Hz take at least 5 / 20 s, so the run's frame rate is at most 6 / (5 / 20) = 24 FPS however
// fast the machine. A negative rate is refused before any output is written.
TEST(RunCli, RateFeedsFramesNoFasterThanASensor) {
  test::TempDir dir("run_cli_rate");
  const auto seq = synth(dir, "office", 6, 0);
  ASSERT_FALSE(seq.empty());
  const auto out = dir / "run";
  auto r = test::run_rrg("run --dataset " + seq.string() + " --out " + out.string() +
                         " --live --rate 20 --device cpu --no-progress --set tsdf.voxel_size=0.02 --set tsdf.truncation=0.08");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto t = nlohmann::json::parse(std::ifstream(out / "timings.json"));
  EXPECT_EQ(t.at("rate_hz").get<double>(), 20.0);
  EXPECT_EQ(t.at("schedule").get<std::string>(), "live");
  EXPECT_LE(t.at("fps").get<double>(), 24.0) << t.dump(2);
  // Each frame's latency runs from its arrival to its pose: positive, the mean within the maximum.
  EXPECT_GT(t.at("input_latency_mean_ms").get<double>(), 0.0);
  EXPECT_LE(t.at("input_latency_mean_ms").get<double>(), t.at("input_latency_max_ms").get<double>());
  EXPECT_NE(r.output.find("input at most 20 Hz"), std::string::npos) << r.output;
  const auto bad = dir / "bad";
  r = test::run_rrg("run --dataset " + seq.string() + " --out " + bad.string() + " --rate -1 --no-progress");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--rate"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(bad));
}

// `rrg run` of seq into dir/run in the background (CPU, 2 cm voxels, `flags`), Ctrl-C once it has
// started: it exits with 128 + SIGINT and its metrics.json, returned, says it was interrupted.
nlohmann::json interrupted_run(const test::TempDir& dir, const std::filesystem::path& seq, const std::string& flags) {
  const auto out = dir / "run";
  test::BackgroundRrg rrg("run --dataset " + seq.string() + " --out " + out.string() +
                              " --device cpu --no-progress --set tsdf.voxel_size=0.02 --set tsdf.truncation=0.08 " + flags,
                          dir / "log.txt");
  // The run has started (and its handler is installed) once it logs its first line.
  const bool started = rrg.wait_for_output("run: ");
  EXPECT_TRUE(started) << "rrg run did not start";
  if (!started) return nlohmann::json::object({{"interrupted", false}, {"frames", 0}});
  rrg.signal(SIGINT);
  EXPECT_EQ(rrg.wait(), 128 + SIGINT);
  auto j = nlohmann::json::parse(std::ifstream(out / "metrics.json"));
  EXPECT_TRUE(j.at("interrupted").get<bool>());
  return j;
}

// Ctrl-C while --rate waits for the next frame (here 2000 s away): the wait ends at once, that frame
// is processed and the run finishes as after any Ctrl-C. Without that, this test would sit out
// CTest's 900 s timeout and fail.
TEST(RunCli, CtrlCEndsARateWait) {
  test::TempDir dir("run_cli_rate_stop");
  const auto seq = synth(dir, "office", 3, 0);
  ASSERT_FALSE(seq.empty());
  const auto j = interrupted_run(dir, seq, "--live --rate 0.0005");
  EXPECT_LE(j.at("frames").get<size_t>(), 2u);  // frame 0, and at most the frame the stop let in
}

// Ctrl-C during a run: the run stops after the current frame and still writes every output over
// the frames it processed, says so in metrics.json, and exits with 128 + SIGINT.
TEST(RunCli, InterruptStopsAfterTheCurrentFrameAndWritesTheOutputs) {
  test::TempDir dir("run_cli_interrupt");
  const auto seq = synth(dir, "living_room", 30, 0);
  ASSERT_FALSE(seq.empty());
  const auto out = dir / "run";
  const auto j = interrupted_run(dir, seq, "--sync");
  const size_t frames = j.at("frames").get<size_t>();
  EXPECT_GE(frames, 1u);
  EXPECT_LT(frames, 30u);
  EXPECT_EQ(j.contains("ate_rmse_cm"), frames >= 3);  // over the frames processed; the alignment needs 3
  std::ifstream traj(out / "trajectory.txt");
  size_t poses = 0;
  for (std::string line; std::getline(traj, line);)
    if (!line.empty() && line[0] != '#') ++poses;
  EXPECT_EQ(poses, frames);
  for (const char* f : {"mesh.ply", "timings.json", "gaussians_base.ply"}) EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
}

}  // namespace
}  // namespace rrg
