// Session snapshots continue exactly: run N frames, save, load into a new session, run the rest;
// the result must be the uninterrupted session's, bit for bit (sync mode; on the CPU with any
// number of threads, see SyncModeIsDeterministic). Also: a v1 file (no continuation section) still
// loads and continues from the last pose.
#include "core/tsdf/tsdf_io.h"
#include "tests/slam/session_fixture.h"

#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace rrg {
namespace {

constexpr size_t kFrames = 30, kSplit = 22;  // N_o = 5: four steps before the split, 2 fused frames pending

class SnapshotTest : public test::SynthSessionTest<SnapshotTest, kFrames> {
 protected:
  // Every stage that carries state across frames: ICP + masked ORB against the keyframes, plane
  // identification, reflection Gaussians, final steps over the mapper's keyframes.
  static SessionConfig config(const io::Dataset& d) {
    SessionConfig c = base_config(d);
    c.tracking.mode = TrackingMode::IcpOrbMask;
    c.plane_period = 1;    // the mirror is accepted before the split: reflection Gaussians and their Adam state
    // ... by frame 22, which leaves no margin: leaving colour edges out of the variance check (on by
    // default) delays the mirror's first windows at 160x120 by a few frames, so it is off here.
    c.planes.variance_skip_color_edges = false;
    c.mapping_period = 5;
    c.final_steps = 2;
    return c;
  }
  static SessionFrame frame(const io::Dataset& d, size_t i) { return SynthSessionTest::frame(d, i, i == 0); }
  static void run(Session& s, const io::Dataset& d, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) s.process(frame(d, i));
  }
};

void expect_same_gaussians(const GaussianHost& a, const GaussianHost& b, const char* set) {
  SCOPED_TRACE(set);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.sh.size(), b.sh.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.means[i], b.means[i]) << "Gaussian " << i;
    ASSERT_EQ(a.log_scales[i], b.log_scales[i]) << "Gaussian " << i;
    ASSERT_EQ(a.quats[i], b.quats[i]) << "Gaussian " << i;
    ASSERT_EQ(a.logit_opacities[i], b.logit_opacities[i]) << "Gaussian " << i;
    ASSERT_EQ(a.plane_ids[i], b.plane_ids[i]) << "Gaussian " << i;
  }
  for (size_t i = 0; i < a.sh.size(); ++i) ASSERT_EQ(a.sh[i], b.sh[i]) << "SH coefficient " << i;
}

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// The v1 form of a v2 snapshot: the v2 payload is the continuation section (u64 length + bytes)
// followed by the v1 payload, so dropping the section and rewriting the header gives the file the
// v1 writer produced.
void write_as_v1(const std::filesystem::path& v2, const std::filesystem::path& v1) {
  const std::vector<uint8_t> b = read_bytes(v2);
  constexpr size_t kHeader = 8 + 4 + 8 + 8;
  ASSERT_GT(b.size(), kHeader + 8);
  uint32_t version;
  std::memcpy(&version, b.data() + 8, 4);
  ASSERT_EQ(version, 2u);
  uint64_t section;
  std::memcpy(&section, b.data() + kHeader, 8);
  const std::span<const uint8_t> payload(b.data() + kHeader + 8 + section, b.size() - kHeader - 8 - section);
  const uint32_t v = 1;
  const uint64_t size = payload.size(), sum = fnv1a64(payload);
  std::ofstream f(v1, std::ios::binary);
  f.write(reinterpret_cast<const char*>(b.data()), 8);
  f.write(reinterpret_cast<const char*>(&v), 4);
  f.write(reinterpret_cast<const char*>(&size), 8);
  f.write(reinterpret_cast<const char*>(&sum), 8);
  f.write(reinterpret_cast<const char*>(payload.data()), std::streamsize(payload.size()));
}

TEST_F(SnapshotTest, ALoadedSessionContinuesLikeTheUninterruptedOne) {
  const auto d = io::open_dataset(root());
  test::TempDir dir("snap-continue");
  Session whole(config(*d));
  run(whole, *d, 0, kFrames);
  whole.finish();

  std::unique_ptr<Session> loaded;
  size_t file_bytes = 0;
  SessionStatus at_save;
  {
    Session first(config(*d));
    run(first, *d, 0, kSplit);
    spdlog::set_level(spdlog::level::debug);  // the save's size breakdown
    first.save(dir / "s.rrgs");
    spdlog::set_level(spdlog::level::info);
    file_bytes = std::filesystem::file_size(dir / "s.rrgs");
    at_save = first.status();
    ASSERT_GT(at_save.keyframes, 1) << "the test needs tracker keyframes before the split";
    ASSERT_GT(at_save.mapping.reflection_gaussians, 0) << "the test needs reflection Gaussians before the split";
    loaded = Session::load(dir / "s.rrgs");
    EXPECT_EQ(loaded->status().keyframes, first.status().keyframes);
    EXPECT_EQ(at_save.mapping.queued, 2);  // the frames pending at the split travel with the snapshot
    EXPECT_EQ(loaded->status().mapping.queued, at_save.mapping.queued);
  }
  run(*loaded, *d, kSplit, kFrames);
  loaded->finish();
  std::printf("[snapshot] %zu frames of %dx%d, %lld tracker keyframes, %lld + %lld Gaussians: %zu bytes\n", kSplit,
              d->intrinsics().width, d->intrinsics().height, (long long)at_save.keyframes,
              (long long)at_save.mapping.base_gaussians, (long long)at_save.mapping.reflection_gaussians, file_bytes);

  const auto ta = whole.trajectory(), tb = loaded->trajectory();
  ASSERT_EQ(ta.size(), tb.size());
  for (size_t i = 0; i < ta.size(); ++i)
    EXPECT_TRUE(ta[i].T_wc.isApprox(tb[i].T_wc, 0.0)) << "frame " << i << ": "
                                                     << (ta[i].T_wc.translation() - tb[i].T_wc.translation()).norm() << " m";
  const SessionStatus sa = whole.status(), sb = loaded->status();
  EXPECT_EQ(sa.keyframes, sb.keyframes);
  EXPECT_EQ(sa.lost, sb.lost);
  EXPECT_EQ(sa.map_version, sb.map_version);
  EXPECT_EQ(sa.mapping.steps, sb.mapping.steps);
  EXPECT_EQ(sa.global_planes, sb.global_planes);
  EXPECT_EQ(sa.reflective_planes, sb.reflective_planes);
  EXPECT_EQ(sa.tsdf_blocks, sb.tsdf_blocks);
  expect_same_gaussians(whole.base_gaussians(), loaded->base_gaussians(), "base");
  expect_same_gaussians(whole.reflection_gaussians(), loaded->reflection_gaussians(), "reflection");
  const TriangleMesh ma = whole.mesh(), mb = loaded->mesh();
  EXPECT_EQ(ma.triangles.size(), mb.triangles.size());
  EXPECT_TRUE(ma.vertices == mb.vertices);
}

// The reflective fill's carried surfaces are in the snapshot. A sensor that sees through the mirror
// and masks on identification frames only (N_p = 10, as the `remote` cue gives them): frames 1-9
// fill from the surface frame 0 left. Saved after frame 4, the loaded session fills frames 5-9 as
// the uninterrupted one does (without the surfaces it would fill none and fuse the room behind).
TEST_F(SnapshotTest, CarriedFillSurfacesSurviveALoad) {
  const auto d = io::open_dataset(root());
  test::TempDir dir("snap-fill");
  const uint16_t mirror_id = category_id("mirror");
  ASSERT_NE(mirror_id, 0);
  SessionConfig c = base_config(*d);
  c.gt_poses = true;
  c.plane_period = 10;
  const auto cue = [] {
    return std::make_unique<test::IdentificationFrameLabels>(make_label_semantics(categories(), default_prompts()));
  };
  const auto seen_through = [&](size_t i) {
    SessionFrame f = SynthSessionTest::frame(*d, i, true);
    for (size_t k = 0; k < f.depth.size(); ++k)
      if ((*f.labels)[k] == mirror_id && f.depth[k] > 0.0f) f.depth[k] += 1.5f;
    return f;
  };
  constexpr size_t kAt = 5, kEnd = 10;
  Session whole(c, cue());
  std::vector<int64_t> expected;
  for (size_t i = 0; i < kEnd; ++i) expected.push_back(whole.process(seen_through(i)).filled_pixels);
  for (size_t i = kAt; i < kEnd; ++i) ASSERT_GT(expected[i], 0) << "frame " << i << " fills from the carried surface";
  std::unique_ptr<Session> loaded;
  {
    Session first(c, cue());
    for (size_t i = 0; i < kAt; ++i) first.process(seen_through(i));
    first.save(dir / "s.rrgs");
    loaded = Session::load(dir / "s.rrgs", cue());
  }
  for (size_t i = kAt; i < kEnd; ++i)
    EXPECT_EQ(loaded->process(seen_through(i)).filled_pixels, expected[i]) << "frame " << i;
  whole.finish();
  loaded->finish();
  const auto ta = whole.trajectory(), tb = loaded->trajectory();
  ASSERT_EQ(ta.size(), tb.size());
  for (size_t i = 0; i < ta.size(); ++i) EXPECT_TRUE(ta[i].T_wc.isApprox(tb[i].T_wc, 0.0)) << "frame " << i;
  EXPECT_EQ(whole.status().tsdf_blocks, loaded->status().tsdf_blocks);
}

// The planes whose reflection vote is open are in the snapshot (continuation v3): the loaded
// session keeps them out of ORB on the next frames as the uninterrupted one does; without them it
// would mask nothing until the next identification frame.
TEST_F(SnapshotTest, UndecidedCandidatesSurviveALoad) {
  const auto d = io::open_dataset(root());
  test::TempDir dir("snap-undecided");
  SessionConfig c = base_config(*d);
  c.tracking.mode = TrackingMode::IcpOrbMask;
  c.plane_period = 10;
  constexpr size_t kAt = 3, kEnd = 6;
  const auto f = [&](size_t i) { return SynthSessionTest::frame(*d, i, i == 0); };
  Session whole(c);
  std::vector<int64_t> expected;
  for (size_t i = 0; i < kEnd; ++i) expected.push_back(whole.process(f(i)).tracking_mask_pixels);
  std::unique_ptr<Session> loaded;
  {
    Session first(c);
    for (size_t i = 0; i < kAt; ++i) first.process(f(i));
    first.save(dir / "s.rrgs");
    loaded = Session::load(dir / "s.rrgs");
  }
  for (size_t i = kAt; i < kEnd; ++i) {
    ASSERT_GT(expected[i], 0) << "frame " << i << " masks the open candidates";
    EXPECT_EQ(loaded->process(f(i)).tracking_mask_pixels, expected[i]) << "frame " << i;
  }
}

TEST_F(SnapshotTest, VersionOneFilesStillLoadAndContinue) {
  const auto d = io::open_dataset(root());
  test::TempDir dir("snap-v1");
  SessionConfig c = config(*d);
  c.tracking.mode = TrackingMode::Icp;  // v1 keeps no ORB keyframes: compare ICP with ICP
  Session s(c);
  constexpr size_t kV1Split = 12;
  run(s, *d, 0, kV1Split);
  s.save(dir / "v2.rrgs");
  write_as_v1(dir / "v2.rrgs", dir / "v1.rrgs");
  const auto v1 = Session::load(dir / "v1.rrgs");
  EXPECT_EQ(v1->status().frames, int64_t(kV1Split));
  EXPECT_EQ(v1->status().keyframes, 0) << "v1 files have no keyframes";
  EXPECT_EQ(v1->status().map_version, s.status().map_version);
  expect_same_gaussians(s.base_gaussians(), v1->base_gaussians(), "base");
  EXPECT_EQ(v1->mesh().triangles.size(), s.mesh().triangles.size());
  std::printf("[snapshot] v2 %ju bytes, as v1 %ju bytes\n", std::uintmax_t(std::filesystem::file_size(dir / "v2.rrgs")),
              std::uintmax_t(std::filesystem::file_size(dir / "v1.rrgs")));
  // Tracking resumes from the last pose against the restored TSDF with no motion prior: ICP
  // converges to the uninterrupted session's pose (the bound the v1 snapshot test asserted).
  const FrameReport ra = s.process(frame(*d, kV1Split));
  const FrameReport rb = v1->process(frame(*d, kV1Split));
  EXPECT_NE(rb.state, TrackingState::Lost);
  EXPECT_LT((ra.T_wc.translation() - rb.T_wc.translation()).norm(), 1e-3);
  // an unknown version is refused
  std::vector<uint8_t> b = read_bytes(dir / "v2.rrgs");
  b[8] = 3;
  std::ofstream(dir / "v3.rrgs", std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
  EXPECT_THROW(Session::load(dir / "v3.rrgs"), std::runtime_error);
}

}  // namespace
}  // namespace rrg
