// SessionConfig: the field table, overrides, YAML files and their round trip.
#include "core/slam/session_config.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

namespace rrg {
namespace {

SessionConfig camera_config() {
  SessionConfig c;
  c.K = {200.f, 200.f, 79.5f, 59.5f, 160, 120};
  return c;
}

// validate() refuses c with an error that names `field`.
void expect_rejected_naming(const SessionConfig& c, const std::string& field, const std::string& what) {
  try {
    c.validate();
    ADD_FAILURE() << what << " accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(SessionConfig, DefaultsAreThePapers) {
  SessionConfig c = camera_config();
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.plane_period, 10);    // N_p
  EXPECT_EQ(c.mapping_period, 10);  // N_o
  EXPECT_FLOAT_EQ(c.tsdf.voxel_size, 0.005f);
  EXPECT_FLOAT_EQ(c.planes.variance_threshold, 0.01f);  // δ_v
  EXPECT_EQ(c.mapping.iterations, 30);
  EXPECT_EQ(c.mapping.n_local, 2);
  EXPECT_EQ(c.mapping.n_global, 7);
}

// The three mapping schedules (mapping_schedule.h): which config gives which, that sync and live
// exclude each other, and when each starts a step.
TEST(SessionConfig, MappingSchedules) {
  SessionConfig c = camera_config();
  EXPECT_EQ(c.schedule(), MappingSchedule::Overlapped);
  apply_override(c, "live=true");
  EXPECT_EQ(c.schedule(), MappingSchedule::Live);
  EXPECT_NO_THROW(c.validate());
  c.sync = true;
  expect_rejected_naming(c, "live", "sync and live together");
  c.live = false;
  EXPECT_EQ(c.schedule(), MappingSchedule::Sync);
  EXPECT_EQ(to_string(MappingSchedule::Live), "live");

  // Sync and overlapped: every N_o-th fused frame, whatever is queued or running.
  for (const MappingSchedule s : {MappingSchedule::Sync, MappingSchedule::Overlapped}) {
    EXPECT_TRUE(mapping_due(s, 10, 20, 10, true));
    EXPECT_TRUE(mapping_due(s, 10, 20, 25, false));
    EXPECT_FALSE(mapping_due(s, 10, 21, 11, false));
  }
  // Live: once N_o frames are queued and no step runs, at any frame count.
  EXPECT_FALSE(mapping_due(MappingSchedule::Live, 10, 20, 10, true));  // never waits for a running step
  EXPECT_TRUE(mapping_due(MappingSchedule::Live, 10, 23, 13, false));  // the first frame after it ended
  EXPECT_FALSE(mapping_due(MappingSchedule::Live, 10, 29, 9, false));  // fewer than N_o queued
  EXPECT_TRUE(mapping_due(MappingSchedule::Live, 1, 1, 1, false));
}

// A live step's iterations: the paper's `iterations` per N_o frames over the frames it covers, never
// fewer than `iterations` (a step right after the one before, or the last of a sequence), at most
// max_scale times them; max_scale 1 keeps every step at `iterations`.
TEST(SessionConfig, LiveStepIterationsFollowTheFramesCovered) {
  EXPECT_EQ(live_step_iterations(30, 10, 10, 2.0), 30);  // mapping keeps up: the paper's step
  EXPECT_EQ(live_step_iterations(30, 10, 3, 2.0), 30);   // fewer than N_o (finish): still a whole step
  EXPECT_EQ(live_step_iterations(30, 10, 0, 2.0), 30);
  EXPECT_EQ(live_step_iterations(30, 10, 15, 2.0), 45);  // 3 per frame
  EXPECT_EQ(live_step_iterations(30, 10, 17, 2.0), 51);
  EXPECT_EQ(live_step_iterations(30, 10, 20, 2.0), 60);
  EXPECT_EQ(live_step_iterations(30, 10, 45, 2.0), 60);  // bounded
  EXPECT_EQ(live_step_iterations(30, 10, 45, 4.0), 120);
  EXPECT_EQ(live_step_iterations(30, 10, 45, 1.0), 30);  // scale 1: every step the same
  EXPECT_EQ(live_step_iterations(30, 10, 45, 0.5), 30);  // below 1 counts as 1
  EXPECT_EQ(live_step_iterations(7, 3, 5, 10.0), 12);    // 7 · 5/3 = 11.67, rounded
  EXPECT_EQ(live_step_iterations(0, 10, 45, 2.0), 0);
  // The config's bound: default 2, at least 1, named when out of range.
  SessionConfig c = camera_config();
  EXPECT_FLOAT_EQ(c.live_step_scale, 2.0f);
  apply_override(c, "live_step_scale=3");
  EXPECT_FLOAT_EQ(c.live_step_scale, 3.0f);
  EXPECT_NO_THROW(c.validate());
  c.live_step_scale = 0.5f;
  expect_rejected_naming(c, "live_step_scale", "a live step scale under 1");
}

// Live's queue bound: within 4 N_o frames nothing goes; beyond it every other non-keyframe goes,
// from the newest back, and every keyframe and the newest frame stay.
TEST(SessionConfig, TheLiveQueueIsThinnedEvenlyKeepingKeyframes) {
  std::vector<bool> key(40, false);
  EXPECT_EQ(thin_live_queue(key, 10).size(), 40u);
  key.assign(41, false);
  key[0] = key[20] = key[21] = true;
  const std::vector<size_t> keep = thin_live_queue(key, 10);
  EXPECT_EQ(keep.back(), 40u);  // the newest
  for (size_t i : {size_t(0), size_t(20), size_t(21)}) EXPECT_NE(std::find(keep.begin(), keep.end(), i), keep.end()) << i;
  EXPECT_TRUE(std::is_sorted(keep.begin(), keep.end()));
  // 38 non-keyframes: 19 kept; never two neighbours among them both dropped or both kept.
  EXPECT_EQ(keep.size(), 3u + 19u);
  std::vector<size_t> plain;
  for (size_t i = 0; i < key.size(); ++i)
    if (!key[i]) plain.push_back(i);
  for (size_t j = 0; j < plain.size(); ++j) {
    const bool kept = std::find(keep.begin(), keep.end(), plain[j]) != keep.end();
    EXPECT_EQ(kept, (plain.size() - 1 - j) % 2 == 0) << plain[j];
  }
}

TEST(SessionConfig, BadIntrinsicsNameTheField) {
  SessionConfig c;
  try {
    c.validate();
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("intrinsics"), std::string::npos) << e.what();
  }
  c = camera_config();
  c.K.cx = 1e6f;
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c = camera_config();
  c.K.width = 100000;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}

TEST(SessionConfig, OverridesSetFieldsAndRejectNonsense) {
  SessionConfig c = camera_config();
  apply_override(c, "tsdf.voxel_size=0.01");
  apply_override(c, "tracking.mode=icp");
  apply_override(c, "sync=true");
  apply_override(c, "mapping_period = 5");
  EXPECT_FLOAT_EQ(c.tsdf.voxel_size, 0.01f);
  EXPECT_EQ(c.tracking.mode, TrackingMode::Icp);
  EXPECT_TRUE(c.sync);
  EXPECT_EQ(c.mapping_period, 5);
  try {
    apply_override(c, "tsdf.voxelsize=0.01");
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {  // suggests the real key
    EXPECT_NE(std::string(e.what()).find("tsdf.voxel_size"), std::string::npos) << e.what();
  }
  EXPECT_THROW(apply_override(c, "tsdf.voxel_size=abc"), std::invalid_argument);
  EXPECT_THROW(apply_override(c, "tsdf.voxel_size=nan"), std::invalid_argument);
  EXPECT_THROW(apply_override(c, "mapping_period=2.5"), std::invalid_argument);
  EXPECT_THROW(apply_override(c, "sync=maybe"), std::invalid_argument);
  EXPECT_THROW(apply_override(c, "no_equals_sign"), std::invalid_argument);
  EXPECT_THROW(apply_override(c, "tracking.mode=orb"), std::invalid_argument);
  EXPECT_FLOAT_EQ(c.tsdf.voxel_size, 0.01f);  // failed overrides change nothing
  // The reflective fill's keys; a value out of range names its field when the config is validated.
  apply_override(c, "planes.fill.enabled=false");
  apply_override(c, "planes.fill.carry=false");
  apply_override(c, "planes.fill.min_sides=3");
  EXPECT_FALSE(c.planes.fill.enabled);
  EXPECT_FALSE(c.planes.fill.carry);
  EXPECT_EQ(c.planes.fill.min_sides, 3);
  apply_override(c, "planes.fill.min_sides=5");
  expect_rejected_naming(c, "planes.fill.min_sides", "min_sides 5");
  apply_override(c, "planes.fill.min_sides=2");
  apply_override(c, "planes.fill.min_region_share=0.7");
  EXPECT_FLOAT_EQ(c.planes.fill.min_region_share, 0.7f);
  c.validate();
  apply_override(c, "planes.fill.min_region_share=1.5");
  expect_rejected_naming(c, "planes.fill.min_region_share", "min_region_share 1.5");
  apply_override(c, "planes.fill.min_region_share=0.5");
  // ICP's noise weighting: its keys, and the sensor's noise model taken from plane segmentation's.
  EXPECT_TRUE(c.tracking_params().icp.noise_weighting);
  apply_override(c, "planes.segmentation.noise_b=0.003");
  apply_override(c, "tracking.icp.noise_reference_depth_m=2");
  apply_override(c, "tracking.icp.huber_delta_m=0.02");
  const TrackingParams t = c.tracking_params();
  EXPECT_FLOAT_EQ(t.icp.noise.b, 0.003f);
  EXPECT_FLOAT_EQ(t.icp.noise.a, c.planes.segmentation.noise.a);
  EXPECT_FLOAT_EQ(t.icp.noise_reference_depth_m, 2.0f);
  EXPECT_FLOAT_EQ(t.icp.huber_delta_m, 0.02f);
  // The TSDF's truncation band uses the same sensor model.
  EXPECT_FLOAT_EQ(c.tsdf_params().band_sigmas, 3.0f);
  EXPECT_FLOAT_EQ(c.tsdf_params().noise.b, 0.003f);
  apply_override(c, "tsdf.band_sigmas=2");
  EXPECT_FLOAT_EQ(c.tsdf_params().band_sigmas, 2.0f);
  c.validate();
  apply_override(c, "tsdf.band_sigmas=-1");
  expect_rejected_naming(c, "band_sigmas", "band_sigmas");
  apply_override(c, "tsdf.band_sigmas=3");
  apply_override(c, "tracking.icp.noise_reference_depth_m=0");
  expect_rejected_naming(c, "noise_reference_depth_m", "noise_reference_depth_m 0");
  apply_override(c, "tracking.icp.noise_weighting=false");
  EXPECT_FALSE(c.tracking_params().icp.noise_weighting);
  c.validate();  // the reference depth is not used then
}

TEST(SessionConfig, YamlFilesAreNestedAndRoundTrip) {
  test::TempDir dir("config");
  {
    std::ofstream f(dir / "a.yaml");
    f << "tsdf:\n  voxel_size: 0.02\n  truncation: 0.08\nplanes:\n  vote:\n    windows: 7\nprompts: [floor, tv]\n";
  }
  SessionConfig c = camera_config();
  load_config_yaml(c, dir / "a.yaml");
  EXPECT_FLOAT_EQ(c.tsdf.voxel_size, 0.02f);
  EXPECT_FLOAT_EQ(c.tsdf.truncation, 0.08f);
  EXPECT_EQ(c.planes.vote.windows, 7);
  ASSERT_EQ(c.prompts.size(), 2u);
  EXPECT_EQ(c.prompts[1], "tv");

  // every field survives config_to_yaml -> load_config_yaml
  c.mapping.reflections = false;
  c.semantics = "none";
  {
    std::ofstream(dir / "b.yaml") << config_to_yaml(c);
  }
  SessionConfig d;
  load_config_yaml(d, dir / "b.yaml");
  auto fc = config_fields(c), fd = config_fields(d);
  ASSERT_EQ(fc.size(), fd.size());
  for (size_t i = 0; i < fc.size(); ++i) EXPECT_EQ(fc[i].get(), fd[i].get()) << fc[i].name;

  {
    std::ofstream(dir / "bad.yaml") << "tsdf:\n  voxel_sise: 0.02\n";
  }
  EXPECT_THROW(load_config_yaml(c, dir / "bad.yaml"), std::runtime_error);
  {
    std::ofstream(dir / "broken.yaml") << "tsdf: [unclosed\n";
  }
  EXPECT_THROW(load_config_yaml(c, dir / "broken.yaml"), std::runtime_error);
  EXPECT_THROW(load_config_yaml(c, dir / "missing.yaml"), std::runtime_error);
}

}  // namespace
}  // namespace rrg
