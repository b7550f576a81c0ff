// Session: the schedule on a small synthetic reflective sequence (real tracking, fusion, plane
// identification and mapping on the CPU), determinism of --sync, bad input, snapshots.
#include "core/eval/trajectory_metrics.h"
#include "core/io/synth_layout.h"
#include "core/planes/plane_metrics.h"
#include "tests/slam/session_fixture.h"

#include <gtest/gtest.h>

#include <set>
#include <omp.h>

#include <atomic>
#include <fstream>
#include <map>
#include <thread>

namespace rrg {
namespace {

class SessionTest : public test::SynthSessionTest<SessionTest, 24> {
 protected:
  static SessionConfig config(const io::Dataset& d) { return base_config(d); }
  static void run(Session& s, const io::Dataset& d, size_t n, bool poses_always) {
    for (size_t i = 0; i < n; ++i) s.process(frame(d, i, poses_always || i == 0));
  }
};

TEST_F(SessionTest, GroundTruthPosesMapAndRender) {
  const auto d = io::open_dataset(root());
  SessionConfig c = config(*d);
  c.gt_poses = true;
  Session s(c);
  run(s, *d, 20, true);
  s.finish();
  const SessionStatus st = s.status();
  EXPECT_EQ(st.frames, 20);
  EXPECT_EQ(st.fused, 20);
  EXPECT_GE(st.mapping.steps, 2);
  EXPECT_GT(st.mapping.base_gaussians, 0);
  EXPECT_GT(st.tsdf_blocks, 0);
  const auto traj = s.trajectory();
  ASSERT_EQ(traj.size(), 20u);
  const auto gt = d->ground_truth();
  for (size_t i = 0; i < traj.size(); ++i)
    EXPECT_LT((traj[i].T_wc.translation() - gt[i].T_wc.translation()).norm(), 1e-6);
  const SessionView v = s.render(c.K, d->load(5).T_wc_gt->cast<float>());
  ASSERT_EQ(v.C.width(), c.K.width);
  double sum = 0;
  for (const Color& px : v.C.pixels()) sum += px.sum();
  EXPECT_GT(sum, 0.0) << "the render is black";
  EXPECT_GT(s.mesh().triangles.size(), 100u);
}

// Auto-exposure (docs/planes.md): frames 0-9 as rendered, frames 10 and 20 (identification frames,
// N_p = 10) through gains 1.3 and 0.75. The session estimates each identification frame's gain
// against the map and reports it; the paper's statistic (exposure_compensation off) reports 1.
TEST_F(SessionTest, IdentificationFramesReportTheirExposureGain) {
  const auto d = io::open_dataset(root());
  for (const bool compensate : {true, false}) {
    SCOPED_TRACE(compensate ? "compensated" : "paper");
    SessionConfig c = config(*d);
    c.gt_poses = true;
    c.planes.exposure_compensation = compensate;
    Session s(c);
    std::map<size_t, float> reported;
    for (size_t i = 0; i <= 20; ++i) {
      SessionFrame f = frame(*d, i, true);
      const float gain = i == 10 ? 1.3f : (i == 20 ? 0.75f : 1.0f);
      for (Color& px : f.color.pixels()) px = (gain * px).cwiseMin(1.0f);
      const FrameReport r = s.process(f);
      if (r.identified) reported[i] = r.exposure_gain;
    }
    ASSERT_EQ(reported.size(), 3u);
    EXPECT_EQ(reported[0], 1.0f) << "an empty map: no estimate";
    // The map's colour averages frames 0-9 (gain 1), then 10-19 (one at 1.3): frame 20 against it.
    EXPECT_NEAR(reported[10], compensate ? 1.3f : 1.0f, 0.02f);
    EXPECT_NEAR(reported[20], compensate ? 0.75f / (1.0f + 0.3f / 20.0f) : 1.0f, 0.03f);
  }
}

// Sensors that lose the mirror (docs/planes.md "Mirrors without depth"): every pixel labelled
// mirror (glass and frame) comes without depth, or with the depth of a point 1.5 m behind it (the
// mirrored room, seen through the glass). With planes.fill the session fills them from the wall
// around the mirror before tracking and fusion, so the TSDF holds a surface there, within a few cm
// of the glass (the wall is 1.5 cm behind it, the frame 3.5 cm in front); without it the map keeps
// the hole, or the room behind the glass.
TEST_F(SessionTest, ALostMirrorIsFilledFromTheWallAroundIt) {
  const auto d = io::open_dataset(root());
  const uint16_t mirror_id = category_id("mirror");
  ASSERT_NE(mirror_id, 0);
  const size_t view = 15;
  const SessionFrame probe = frame(*d, view, true);
  int64_t mirror_px = 0;
  for (const uint16_t l : probe.labels->pixels()) mirror_px += l == mirror_id;
  ASSERT_GT(mirror_px, int64_t(probe.labels->size() / 20)) << "the mirror is not in view";
  for (const bool through : {false, true})
    for (const bool fill : {true, false}) {
      SCOPED_TRACE(std::string(through ? "seen through" : "lost") + (fill ? ", fill" : ", no fill"));
      SessionConfig c = config(*d);
      c.gt_poses = true;
      c.planes.fill.enabled = fill;
      Session s(c);
      int64_t filled = 0;
      for (size_t i = 0; i < 20; ++i) {
        SessionFrame f = frame(*d, i, true);
        for (size_t k = 0; k < f.depth.size(); ++k)
          if ((*f.labels)[k] == mirror_id) f.depth[k] = through && f.depth[k] > 0.0f ? f.depth[k] + 1.5f : 0.0f;
        filled += s.process(f).filled_pixels;
      }
      s.finish();
      const SessionView v = s.render(c.K, *probe.pose);
      int64_t with_depth = 0, close = 0, behind = 0;
      for (size_t k = 0; k < v.depth.size(); ++k) {
        if ((*probe.labels)[k] != mirror_id) continue;
        const float z = v.depth[k], z_true = probe.depth[k];
        with_depth += z > 0.0f;
        close += z > 0.0f && z_true > 0.0f && std::abs(z - z_true) < 0.05f;
        behind += z > 0.0f && z_true > 0.0f && z > z_true + 1.0f;
      }
      if (fill) {
        EXPECT_GT(filled, 20 * mirror_px / 4) << "frames filled";
        EXPECT_GT(close, mirror_px * 8 / 10) << with_depth << " of " << mirror_px << " mirror pixels with depth";
      } else {
        EXPECT_EQ(filled, 0);
        if (through) EXPECT_GT(behind, mirror_px / 2) << "the room behind the glass is in the map";
        else EXPECT_LT(with_depth, mirror_px / 10) << "the hole is in the map";
      }
    }
}


// A sensor that sees through the mirror, with masks on identification frames only (the `remote`
// cue): frames 0 and 10 fill from their masks, the 18 frames between from the surface those fills
// left (FillRegion, at the tracked pose), so the map holds the glass, not the room behind it.
TEST_F(SessionTest, FramesWithoutMasksFillFromTheLastFill) {
  const auto d = io::open_dataset(root());
  const uint16_t mirror_id = category_id("mirror");
  ASSERT_NE(mirror_id, 0);
  for (const bool carry : {true, false}) {
    SCOPED_TRACE(carry ? "carry" : "no carry");
    SessionConfig c = config(*d);
    c.gt_poses = true;
    c.planes.fill.carry = carry;
    auto cue = std::make_unique<test::IdentificationFrameLabels>(make_label_semantics(categories(), default_prompts()));
    test::IdentificationFrameLabels* probe_cue = cue.get();
    Session s(c, std::move(cue));
    std::vector<int64_t> filled(20, 0);
    for (size_t i = 0; i < 20; ++i) {
      SessionFrame f = frame(*d, i, true);
      for (size_t k = 0; k < f.depth.size(); ++k)
        if ((*f.labels)[k] == mirror_id && f.depth[k] > 0.0f) f.depth[k] += 1.5f;
      filled[i] = s.process(f).filled_pixels;
    }
    s.finish();
    EXPECT_EQ(probe_cue->calls, 2) << "masks on frames 0 and 10 only";
    for (size_t i = 0; i < 20; ++i) EXPECT_EQ(filled[i] > 0, carry || i % 10 == 0) << "frame " << i;
    const SessionFrame probe = frame(*d, 15, true);
    const SessionView v = s.render(c.K, *probe.pose);
    int64_t mirror_px = 0, close = 0, behind = 0;
    for (size_t k = 0; k < v.depth.size(); ++k) {
      if ((*probe.labels)[k] != mirror_id || !(probe.depth[k] > 0.0f)) continue;
      ++mirror_px;
      close += v.depth[k] > 0.0f && std::abs(v.depth[k] - probe.depth[k]) < 0.05f;
      behind += v.depth[k] > probe.depth[k] + 1.0f;
    }
    ASSERT_GT(mirror_px, 0);
    if (carry) {
      EXPECT_GT(close, mirror_px * 8 / 10);
      EXPECT_LT(behind, mirror_px / 20) << "the room behind the glass is in the map";
    } else {
      EXPECT_GT(behind, mirror_px / 10) << "the frames between fuse the room behind the glass";
    }
  }
}

// Masks on every frame (labels), a sensor that sees through the mirror, and a segmenter that fails
// on frames 5-9: it misses the mirror on 5-7 (labelled wall) and gives only its middle on 8-9 (the
// mask eroded by 6 px: its ring is glass seen through, no plane to fill from). The surfaces earlier
// fills found (FillRegion) fill those frames as they fill frames without masks, so no frame fuses
// the mirrored room; without the carry those five frames put it in the map behind the glass.
TEST_F(SessionTest, MasksThatFailOrAreMissedFillFromEarlierFills) {
  const auto d = io::open_dataset(root());
  const uint16_t mirror_id = category_id("mirror"), wall_id = category_id("wall");
  ASSERT_NE(mirror_id, 0);
  ASSERT_NE(wall_id, 0);
  const auto corrupt = [&](LabelImage& labels, size_t i) {
    if (i < 5 || i > 9) return;
    const LabelImage in = labels;
    const int w = in.width(), h = in.height(), k = 6;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        if (in(u, v) != mirror_id) continue;
        bool inner = i >= 8;
        for (int dv = -k; dv <= k && inner; ++dv)
          for (int du = -k; du <= k && inner; ++du) {
            const int x = u + du, y = v + dv;
            inner = x >= 0 && y >= 0 && x < w && y < h && in(x, y) == mirror_id;
          }
        if (!inner) labels(u, v) = wall_id;
      }
  };
  for (const bool carry : {true, false}) {
    SCOPED_TRACE(carry ? "carry" : "no carry");
    SessionConfig c = config(*d);
    c.gt_poses = true;
    c.planes.fill.carry = carry;
    Session s(c);
    std::vector<int64_t> filled(20, 0);
    for (size_t i = 0; i < 20; ++i) {
      SessionFrame f = frame(*d, i, true);
      for (size_t k = 0; k < f.depth.size(); ++k)
        if ((*f.labels)[k] == mirror_id && f.depth[k] > 0.0f) f.depth[k] += 1.5f;
      corrupt(*f.labels, i);
      filled[i] = s.process(f).filled_pixels;
    }
    s.finish();
    for (size_t i = 0; i < 20; ++i) EXPECT_EQ(filled[i] > 0, carry || i < 5 || i > 9) << "frame " << i;
    // Map vertices seen through the probe view's mirror pixels, more than 0.5 m behind the glass.
    const SessionFrame probe = frame(*d, 15, true);
    const Eigen::Isometry3f T_cw = probe.pose->inverse();
    int64_t behind = 0;
    for (const Eigen::Vector3f& p_w : s.mesh().vertices) {
      const Eigen::Vector3f p = T_cw * p_w;
      if (!(p.z() > 0.1f)) continue;
      const Eigen::Vector2f uv = c.K.project(p);
      const int u = int(std::lround(uv.x())), v = int(std::lround(uv.y()));
      if (u < 0 || v < 0 || u >= c.K.width || v >= c.K.height || (*probe.labels)(u, v) != mirror_id) continue;
      behind += probe.depth(u, v) > 0.0f && p.z() > probe.depth(u, v) + 0.5f;
    }
    if (carry) EXPECT_EQ(behind, 0) << "the mirrored room is in the map";
    else EXPECT_GT(behind, 100) << "the five frames did not fuse the room behind the glass";
  }
}

// Tracking with a sensor that sees through the mirror's glass, which here fills about two thirds of
// every frame. The fill writes the wall's plane over the glass for the map, but tracking leaves out
// the pixels it wrote: a plane fitted a little off from frame to frame (a mask short of the glass
// takes in its frame, docs/planes.md) would move the pose, and the room seen through the glass is no
// surface of the map. Every frame tracks Ok. Only the glass (the reflective GT plane of the mirror)
// reports the mirrored depth; its frame, labelled "mirror" as a segmenter labels it, stays at its
// depth as any sensor sees it. Measured over the 24 frames: 0.12 cm, as with the glass's own depth.
// (Until 2026-12-07 this test pushed every "mirror"-labelled pixel back, frame included, which no
// sensor does: what was left of the frame was the wall and a strip of floor, two planes free along
// their crease, and the ATE was 12.8 cm; docs/tracking.md.)
TEST_F(SessionTest, TrackingLeavesOutTheFilledGlass) {
  const auto d = io::open_dataset(root());
  int glass = 0;
  for (const auto& [id, p] : read_gt_planes(io::synth_scene_file(root(), "planes.json")))
    if (p.category == "mirror" && p.reflective) glass = id;
  ASSERT_NE(glass, 0) << "no reflective mirror plane in planes.json";
  io::Trajectory gt = d->ground_truth();
  gt.resize(24);
  for (const bool through : {false, true}) {
    SCOPED_TRACE(through ? "seen through" : "the glass with its depth");
    Session s(config(*d));
    int64_t filled = 0;
    for (size_t i = 0; i < 24; ++i) {
      SessionFrame f = frame(*d, i, i == 0);
      if (through) {
        const LabelImage planes = io::read_synth_planes(root(), i);
        for (size_t k = 0; k < f.depth.size(); ++k)
          if (planes[k] == glass && f.depth[k] > 0.0f) f.depth[k] += 1.5f;
      }
      const FrameReport r = s.process(f);
      filled += r.filled_pixels;
      EXPECT_EQ(r.state, TrackingState::Ok) << "frame " << i << ": " << r.note;
    }
    s.finish();
    const auto m = eval::evaluate_trajectory(s.trajectory(), gt);
    EXPECT_EQ(filled > 24 * 5000, through) << filled << " pixels filled";
    EXPECT_LT(m.ate.rmse_cm, 0.5) << "ATE " << m.ate.rmse_cm << " cm";
  }
}

TEST_F(SessionTest, TheTrackingMaskKeepsOutReflectionsNotModelledYet) {
  // Frame 0 is an identification frame: the planes under the labels of reflective categories
  // (mirror, floor, table) become candidates whose vote is open, and no reflection Gaussian renders
  // them yet. The paper's C_r test alone masks nothing on frame 1; with mask_unmodelled the
  // mask covers those planes and no other pixel.
  const auto d = io::open_dataset(root());
  const SessionFrame f1 = frame(*d, 1, false);
  const std::set<uint16_t> reflective = {category_id("mirror"), category_id("floor"), category_id("table")};
  int64_t mirror = 0, candidates = 0;
  for (const uint16_t l : f1.labels->pixels()) {
    mirror += l == category_id("mirror");
    candidates += l != 0 && reflective.count(l);
  }
  ASSERT_GT(mirror, int64_t(f1.depth.size() / 10));
  std::map<std::pair<int, bool>, int64_t> masked;  // by mask_downsample, mask_warp
  struct Case {
    bool unmodelled;
    int downsample;
    bool warp;
  };
  for (const Case k : {Case{true, 1, true}, Case{true, 1, false}, Case{true, 2, true}, Case{false, 2, true}}) {
    SCOPED_TRACE((k.unmodelled ? "mask_unmodelled, downsample " : "C_r test alone, downsample ") +
                 std::to_string(k.downsample) + (k.warp ? ", warped plane ids" : ", raycast plane ids"));
    const bool unmodelled = k.unmodelled;
    SessionConfig c = config(*d);
    c.tracking.mode = TrackingMode::IcpOrbMask;
    c.tracking.orb.mask_unmodelled = unmodelled;
    c.tracking.orb.mask_downsample = k.downsample;
    c.tracking.orb.mask_warp = k.warp;
    Session s(c);
    ASSERT_TRUE(s.process(frame(*d, 0, true)).identified);
    const FrameReport r = s.process(f1);
    EXPECT_EQ(r.state, TrackingState::Ok) << r.note;
    if (unmodelled) {
      masked[{k.downsample, k.warp}] = r.tracking_mask_pixels;
      EXPECT_GT(r.tracking_mask_pixels, mirror * 9 / 10) << "the mirror's plane is masked";
      // (+25 %: a raycast pixel takes the plane id of its nearest voxel, 2 cm here, so the planes
      // spill over their labels' borders by about a voxel.)
      EXPECT_LT(r.tracking_mask_pixels, candidates * 5 / 4) << "only the candidates' planes are";
    } else {
      EXPECT_EQ(r.tracking_mask_pixels, 0);
    }
  }
  // Rendered at half the size, each mask pixel covering 2 x 2: the same area to within its border.
  const double full = double(masked[{1, true}]);
  EXPECT_NEAR(double(masked[{2, true}]), full, 0.05 * full);
  // The plane ids warped from frame 0's model raycast (the default) against a raycast at frame 1's
  // ICP pose: the same area to within a pixel along the planes' outlines, where a pixel may go
  // either way (the warp writes the pixel centres within a pixel of each point, the nearest
  // winning). Where it lands, pixel for pixel, is raycast_warp_test.cpp's.
  EXPECT_NEAR(double(masked[{1, false}]), full, 0.05 * full);
}

TEST_F(SessionTest, TracksTheSequence) {
  const auto d = io::open_dataset(root());
  Session s(config(*d));
  run(s, *d, 24, false);
  s.finish();
  io::Trajectory gt = d->ground_truth();
  gt.resize(24);
  const auto m = eval::evaluate_trajectory(s.trajectory(), gt);
  EXPECT_LT(m.ate.rmse_cm, 2.0) << "ATE " << m.ate.rmse_cm << " cm";
  EXPECT_EQ(s.status().lost, 0);
}

TEST_F(SessionTest, SyncModeIsDeterministic) {
  // The same trajectory, TSDF and Gaussians bit for bit whatever the CPU thread count (docs/slam.md):
  // one run on one thread, the other on three.
  const int threads = omp_get_max_threads();
  const auto d = io::open_dataset(root());
  Session a(config(*d)), b(config(*d));
  omp_set_num_threads(1);
  run(a, *d, 21, false);
  omp_set_num_threads(3);
  run(b, *d, 21, false);
  omp_set_num_threads(threads);
  const auto ta = a.trajectory(), tb = b.trajectory();
  ASSERT_EQ(ta.size(), tb.size());
  for (size_t i = 0; i < ta.size(); ++i) EXPECT_TRUE(ta[i].T_wc.isApprox(tb[i].T_wc, 0.0)) << "frame " << i;
  const GaussianHost ga = a.base_gaussians(), gb = b.base_gaussians();
  ASSERT_GT(ga.size(), 0u);
  ASSERT_EQ(ga.size(), gb.size());
  for (size_t i = 0; i < ga.size(); ++i) {
    ASSERT_EQ(ga.means[i], gb.means[i]) << "Gaussian " << i;
    ASSERT_EQ(ga.logit_opacities[i], gb.logit_opacities[i]) << "Gaussian " << i;
  }
  EXPECT_EQ(ga.sh, gb.sh);
  EXPECT_EQ(a.reflection_gaussians().means, b.reflection_gaussians().means);
  EXPECT_EQ(a.mesh().triangles.size(), b.mesh().triangles.size());
}

TEST_F(SessionTest, BadFramesAreRejectedAndTheSessionGoesOn) {
  const auto d = io::open_dataset(root());
  Session s(config(*d));
  s.process(frame(*d, 0, true));
  SessionFrame small = frame(*d, 1, false);
  small.depth = DepthImage(80, 60, 1.0f);
  EXPECT_THROW(s.process(small), std::invalid_argument);
  SessionFrame old = frame(*d, 1, false);
  old.index = 0;  // not above the last id
  EXPECT_THROW(s.process(old), std::invalid_argument);
  EXPECT_EQ(s.status().frames, 1);
  const FrameReport r = s.process(frame(*d, 1, false));
  EXPECT_NE(r.state, TrackingState::Lost);
  EXPECT_EQ(s.status().frames, 2);
}

TEST_F(SessionTest, RendersWhileMappingRuns) {
  const auto d = io::open_dataset(root());
  SessionConfig c = config(*d);
  c.sync = false;  // mapping on its own thread
  Session s(c);
  std::atomic<bool> done{false};
  std::atomic<int> renders{0};
  const Eigen::Isometry3f T = d->load(0).T_wc_gt->cast<float>();
  std::thread viewer([&] {
    while (!done) {
      const SessionView v = s.render(c.K, T);
      EXPECT_EQ(v.C.width(), c.K.width);
      ++renders;
    }
  });
  run(s, *d, 24, false);
  s.finish();
  done = true;
  viewer.join();
  EXPECT_GT(renders.load(), 0);
  EXPECT_GE(s.status().mapping.steps, 2);
}

// Live: pre-mapping never waits for a running step. Steps are made slow (200 iterations each, a
// second or more here) against frames processed as fast as they come (tens of ms), so a step is
// still running at the next N_o boundary: the overlapped schedule waits there, the live one goes
// on, and its next step starts once the running one has ended, with every frame queued since.
TEST_F(SessionTest, LiveMappingNeverWaitsForARunningStep) {
  const auto d = io::open_dataset(root());
  MappingSummary overlapped, live;
  for (const bool is_live : {false, true}) {
    SessionConfig c = config(*d);
    c.sync = false;
    c.live = is_live;
    c.mapping.iterations = 200;
    Session s(c);
    run(s, *d, 24, false);
    s.finish();  // maps the frames still queued
    (is_live ? live : overlapped) = s.status().mapping;
    EXPECT_EQ(s.status().fused, 24);
    EXPECT_EQ(s.status().mapping.queued, 0);  // finish() handed every queued frame to a step
    EXPECT_EQ(s.status().mapping.thinned, 0);  // 14 at most queued: within the live bound
    EXPECT_GT(s.status().mapping.base_gaussians, 0);
  }
  EXPECT_GE(overlapped.waits, 1);  // the step at frame 20 waited for the one from frame 10
  EXPECT_EQ(overlapped.steps, 3);  // frames 10 and 20, and the 4 left at finish()
  EXPECT_EQ(live.waits, 0);        // whatever the timing: a live step starts only when none runs
  EXPECT_GE(live.steps, 2);        // the first at frame 10, the queued rest at the latest at finish()
  EXPECT_LE(live.steps, overlapped.steps);  // 2 when the first step outlasts frames 11-24, as here
  EXPECT_EQ(overlapped.iterations, overlapped.steps * 200);  // only live steps scale their iterations
  // Live (live_step_iterations, bound 2): the step at frame 10 covers 10 frames, 200 iterations; when
  // it outlasts frames 11-24, finish() maps those 14 in one step of 200 · 14/10 = 280. Otherwise a
  // second step started at frame 20-23 (10-13 frames: 200-260) and finish() took the rest (200).
  if (live.steps == 2)
    EXPECT_EQ(live.iterations, 480);
  else
    EXPECT_TRUE(live.iterations >= 600 && live.iterations <= 660 && live.iterations % 20 == 0) << live.iterations;
}

TEST_F(SessionTest, SnapshotRestoresTheMapAndContinues) {
  const auto d = io::open_dataset(root());
  test::TempDir dir("snap");
  Session s(config(*d));
  run(s, *d, 20, false);
  s.flush();
  s.save(dir / "s.rrgs");
  const auto loaded = Session::load(dir / "s.rrgs");
  EXPECT_EQ(loaded->mesh().triangles.size(), s.mesh().triangles.size());
  const GaussianHost a = s.base_gaussians(), b = loaded->base_gaussians();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.means[i], b.means[i]);
  EXPECT_EQ(loaded->reflection_gaussians().size(), s.reflection_gaussians().size());
  EXPECT_EQ(loaded->status().frames, 20);
  EXPECT_EQ(loaded->status().global_planes, s.status().global_planes);
  const auto ta = s.trajectory(), tb = loaded->trajectory();
  ASSERT_EQ(ta.size(), tb.size());
  EXPECT_TRUE(ta.back().T_wc.isApprox(tb.back().T_wc, 1e-6));
  // both continue the same way from the restored state
  const FrameReport ra = s.process(frame(*d, 20, false));
  const FrameReport rb = loaded->process(frame(*d, 20, false));
  EXPECT_NE(rb.state, TrackingState::Lost);
  EXPECT_LT((ra.T_wc.translation() - rb.T_wc.translation()).norm(), 1e-3);

  // corrupt and truncated snapshots are refused with a message
  std::vector<char> bytes;
  {
    std::ifstream f(dir / "s.rrgs", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  bytes[bytes.size() / 2] ^= 0x55;
  std::ofstream(dir / "bad.rrgs", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  EXPECT_THROW(Session::load(dir / "bad.rrgs"), std::runtime_error);
  std::ofstream(dir / "short.rrgs", std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 3));
  EXPECT_THROW(Session::load(dir / "short.rrgs"), std::runtime_error);
  EXPECT_THROW(Session::load(dir / "missing.rrgs"), std::runtime_error);
}

}  // namespace
}  // namespace rrg
