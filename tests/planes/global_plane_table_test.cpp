// The global plane table: geometric filter, footprint overlap / bbox IoU / gap rules, best-overlap
// choice, union-find merges and the remap table, each on hand-made floor patches (world z = 0).
#include "core/planes/global_plane_table.h"

#include "core/planes/plane_state_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace rrg {
namespace {

// A rectangle [x0, x1] x [y0, y1] of points every 1 cm on the plane z = h (normal +z).
LocalObservation patch(int local_id, float x0, float x1, float y0, float y1, float h = 0.0f) {
  LocalObservation o;
  o.local_id = local_id;
  o.plane = {Eigen::Vector3f::UnitZ(), -h};
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  const int nx = int(std::lround((x1 - x0) / 0.01f)), ny = int(std::lround((y1 - y0) / 0.01f));
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) {
      o.points.emplace_back(x0 + 0.01f * float(i), y0 + 0.01f * float(j), h);
      sum += o.points.back();
    }
  o.centroid = sum / float(o.points.size());
  return o;
}

// Points every 1 cm over [x0, x1] x [y0, y1] at height z(x) plus uniform noise of standard deviation
// sigma (fixed seed), with the plane and centroid the segmenter would report: fitted to the points.
template <class Height>
LocalObservation noisy_patch(int local_id, float x0, float x1, float y0, float y1, Height z, float sigma, uint32_t seed) {
  std::mt19937 rng(seed);
  const float half_width = sigma * std::sqrt(3.0f);
  LocalObservation o;
  o.local_id = local_id;
  PlaneMoments m;
  const int nx = int(std::lround((x1 - x0) / 0.01f)), ny = int(std::lround((y1 - y0) / 0.01f));
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) {
      const float x = x0 + 0.01f * float(i), u = float(rng()) / 4294967296.0f;
      o.points.emplace_back(x, y0 + 0.01f * float(j), z(x) + half_width * (2.0f * u - 1.0f));
      m.add(o.points.back());
    }
  const PlaneFit fit = fit_plane(m, Eigen::Vector3f(0, 0, 10));  // seen from above
  o.plane = fit.plane;
  o.centroid = fit.centroid;
  return o;
}

int associate_one(GlobalPlaneTable& t, const LocalObservation& o, int64_t frame) {
  const LocalObservation obs[] = {o};
  return t.associate(obs, frame).local_to_global.at(size_t(o.local_id));
}

TEST(GlobalPlaneTable, OverlapRuleMatchesAndUpdatesFootprint) {
  GlobalPlaneTable t;
  EXPECT_EQ(associate_one(t, patch(1, 0, 1, 0, 1), 0), 1);
  const size_t cells_before = t.find(1)->footprint.cells();
  EXPECT_EQ(associate_one(t, patch(1, 0.5f, 1.5f, 0, 1), 100), 1);  // half overlapping, long after
  EXPECT_GT(t.find(1)->footprint.cells(), cells_before);
  const Box2& box = t.find(1)->footprint.box();
  EXPECT_NEAR(box.max.x() - box.min.x(), 1.5f, 0.011f);  // the box grew to cover both patches
  EXPECT_EQ(t.live_ids().size(), 1u);
  EXPECT_EQ(t.find(1)->observations, 2);
}

TEST(GlobalPlaneTable, GeometricFilterRejectsDistanceAndAngle) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);
  EXPECT_EQ(associate_one(t, patch(1, 0, 1, 0, 1, 0.15f), 1), 2);  // 15 cm above: new instance
  EXPECT_EQ(associate_one(t, patch(1, 0, 1, 0, 1, 0.08f), 2), 1);  // 8 cm: same instance as the first
  LocalObservation tilted = patch(1, 0, 1, 0, 1);
  const Eigen::AngleAxisf r(15.0f * 3.14159265f / 180.0f, Eigen::Vector3f::UnitX());
  for (auto& p : tilted.points) p = r * (p - tilted.centroid) + tilted.centroid;
  tilted.plane = {r * Eigen::Vector3f::UnitZ(), -(r * Eigen::Vector3f::UnitZ()).dot(tilted.centroid)};
  EXPECT_EQ(associate_one(t, tilted, 3), 3);  // 15° tilt: new instance
}

TEST(GlobalPlaneTable, BoxIouRuleMatchesWithoutCellOverlap) {
  GlobalPlaneTable t;
  // Two small squares at opposite corners of [0, 2]²: one instance (the second matches by IoU).
  LocalObservation corners = patch(1, 0, 0.2f, 0, 0.2f);
  const LocalObservation far = patch(1, 1.8f, 2.0f, 1.8f, 2.0f);
  corners.points.insert(corners.points.end(), far.points.begin(), far.points.end());
  corners.centroid = Eigen::Vector3f(1, 1, 0);
  ASSERT_EQ(associate_one(t, corners, 0), 1);
  // Middle square 0.4 x 0.4: no cell overlap, IoU = 0.16 / 4 = 0.04 > 0.02, not recent (frame 500).
  const LocalObservation middle = patch(1, 0.8f, 1.2f, 0.8f, 1.2f);
  const auto scores = t.score(middle, 500);
  ASSERT_EQ(scores.size(), 1u);
  EXPECT_EQ(scores[0].overlap, 0.0f);
  EXPECT_NEAR(scores[0].iou, 0.04f, 0.005f);
  EXPECT_FALSE(scores[0].recent);
  EXPECT_TRUE(scores[0].matched);
  // A 0.1 x 0.1 square away from the corners and the middle has IoU 0.0025, is not recent: new.
  EXPECT_EQ(associate_one(t, patch(1, 0.3f, 0.4f, 1.5f, 1.6f), 500), 2);
  EXPECT_EQ(associate_one(t, middle, 501), 1);
}

TEST(GlobalPlaneTable, GapRuleOnlyForRecentInstances) {
  GlobalPlaneParams params;
  params.recent_frames = 30;
  {
    GlobalPlaneTable t(params);
    associate_one(t, patch(1, 0, 0.99f, 0, 1), 0);
    const LocalObservation beside = patch(1, 1.07f, 2.0f, 0, 1);  // 8 cm gap
    const auto s = t.score(beside, 10);
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].overlap, 0.0f);
    EXPECT_EQ(s[0].iou, 0.0f);
    EXPECT_NEAR(s[0].gap, 0.08f, 0.002f);
    EXPECT_EQ(associate_one(t, beside, 10), 1);  // seen 10 frames ago: recent
  }
  {
    GlobalPlaneTable t(params);
    associate_one(t, patch(1, 0, 0.99f, 0, 1), 0);
    EXPECT_EQ(associate_one(t, patch(1, 1.07f, 2.0f, 0, 1), 100), 2);  // 100 frames later: new
  }
  {
    GlobalPlaneTable t(params);
    associate_one(t, patch(1, 0, 0.99f, 0, 1), 0);
    EXPECT_EQ(associate_one(t, patch(1, 1.15f, 2.0f, 0, 1), 10), 2);  // 16 cm gap: new
  }
}

TEST(GlobalPlaneTable, BestOverlapWinsAmongMatchingCandidates) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);        // id 1
  associate_one(t, patch(1, 1.5f, 2.5f, 0, 1), 0);  // id 2 (gap 0.5 m)
  ASSERT_EQ(t.live_ids().size(), 2u);
  const LocalObservation bridge = patch(1, 0.9f, 2.5f, 0, 1);
  const auto scores = t.score(bridge, 1);
  ASSERT_EQ(scores.size(), 2u);
  EXPECT_TRUE(scores[0].matched && scores[1].matched);
  EXPECT_GT(scores[1].overlap, scores[0].overlap);
  const LocalObservation obs[] = {bridge};
  const FrameAssociation a = t.associate(obs, 1);
  EXPECT_EQ(a.local_to_global[1], 2);  // the higher overlap, not a bridge of both
  EXPECT_TRUE(a.merges.empty());
  EXPECT_EQ(t.live_ids().size(), 2u);
}

// The highest-overlap choice keeps one segment from bridging two instances (above); a second frame
// in which a piece of one is one surface with the other is evidence, and merges them. The record of
// the first frame survives a snapshot of the table, with each instance's closest-look tolerance.
TEST(GlobalPlaneTable, TwoFramesOfOneSurfaceBridgingTwoInstancesMergeThem) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);        // 1
  LocalObservation far = patch(1, 1.5f, 2.5f, 0, 1);
  far.same_plane_distance = 0.02f;
  associate_one(t, far, 0);                         // 2, seen from farther away
  const LocalObservation bridge = patch(1, 0.9f, 2.5f, 0, 1);
  EXPECT_EQ(associate_one(t, bridge, 10), 2);
  EXPECT_EQ(t.live_ids().size(), 2u);               // one frame: no merge
  ASSERT_EQ(t.find(2)->bridged.size(), 1u);
  EXPECT_FLOAT_EQ(t.find(2)->same_plane_distance, 0.01f);  // the bridge was the closer look

  io::ByteWriter w;
  PlaneStateIo::write_table(w, t);
  GlobalPlaneTable loaded;
  io::ByteReader r(w.bytes(), "table");
  PlaneStateIo::read_table(r, loaded, 3);
  EXPECT_FLOAT_EQ(loaded.find(1)->same_plane_distance, 0.01f);
  EXPECT_FLOAT_EQ(loaded.find(2)->same_plane_distance, 0.01f);

  const LocalObservation again[] = {bridge};
  const FrameAssociation a = loaded.associate(again, 20);
  EXPECT_EQ(a.local_to_global[1], 1);
  EXPECT_EQ(a.merges, (std::vector<std::pair<int, int>>{{1, 2}}));
  EXPECT_EQ(loaded.live_ids(), (std::vector<int>{1}));
}

// A segment on the plane z = 0 that also matches an instance 5 cm above it (within the 0.1 m
// filter, overlapping its footprint's edge) is not one surface with it: repeated, it merges nothing.
TEST(GlobalPlaneTable, ABridgeToAnotherLayerMergesNothing) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);                 // 1: z = 0
  associate_one(t, patch(1, 1.5f, 2.5f, 0, 1, 0.05f), 0);    // 2: z = 5 cm
  const LocalObservation bridge = patch(1, 0.9f, 1.6f, 0, 1);  // reaches 10 cm under 2
  const auto scores = t.score(bridge, 10);
  ASSERT_EQ(scores.size(), 2u);
  ASSERT_TRUE(scores[0].matched && scores[1].matched);
  for (int64_t frame : {10, 20, 30}) {
    EXPECT_EQ(associate_one(t, bridge, frame), 1);
    EXPECT_TRUE(t.find(1)->bridged.empty());
  }
  EXPECT_EQ(t.live_ids().size(), 2u);
}

TEST(GlobalPlaneTable, UnionFindMergeLowerIdAbsorbsHigherAndRemaps) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);                 // 1
  associate_one(t, patch(1, 3, 4, 0, 1), 0);                 // 2: far away, no rule matches
  associate_one(t, patch(1, 6, 7, 0, 1), 0);                 // 3
  ASSERT_EQ(t.live_ids(), (std::vector<int>{1, 2, 3}));
  const size_t cells = t.find(1)->footprint.cells() + t.find(2)->footprint.cells() + t.find(3)->footprint.cells();
  EXPECT_TRUE(t.merge(3, 2));
  EXPECT_EQ(t.canonical(3), 2);
  EXPECT_TRUE(t.merge(2, 1));
  EXPECT_FALSE(t.merge(1, 3));  // already one instance
  EXPECT_EQ(t.canonical(3), 1);
  EXPECT_EQ(t.remap_table(), (std::vector<int32_t>{0, 1, 1, 1}));
  EXPECT_EQ(t.live_ids(), (std::vector<int>{1}));
  const GlobalPlane* g = t.find(3);
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->id, 1);
  EXPECT_EQ(g->footprint.cells(), cells);
  EXPECT_NEAR(g->footprint.box().min.x() - g->footprint.box().max.x(), -7.0f, 0.02f);  // spans x 0..7
  EXPECT_NEAR(std::abs(g->plane.n.z()), 1.0f, 1e-5f);
  EXPECT_NEAR(g->plane.d, 0.0f, 1e-4f);
  EXPECT_NEAR(g->centroid.x(), 3.5f, 0.01f);
  // The global map goes through the remap table.
  LabelImage local(2, 1, 0);
  local(0, 0) = 1;
  FrameAssociation a;
  a.local_to_global = {0, 3};
  const Image<int32_t> map = t.global_map(local, a);
  EXPECT_EQ(map(0, 0), 1);
  EXPECT_EQ(map(1, 0), 0);
}

TEST(GlobalPlaneTable, MergePassJoinsInstancesThatTurnOutToBeOnePlane) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);  // 1
  associate_one(t, patch(1, 3, 4, 0, 1), 0);  // 2
  // Later the whole floor is seen at once: it matches both, grows one, and the instances merge.
  const LocalObservation all[] = {patch(1, 0, 4, 0, 1)};
  const FrameAssociation a = t.associate(all, 50);
  ASSERT_EQ(a.merges.size(), 1u);
  EXPECT_EQ(a.merges[0], std::make_pair(1, 2));
  EXPECT_EQ(a.local_to_global[1], 1);
  EXPECT_EQ(t.canonical(2), 1);
}

// A mirror and its frame's bar 3.5 cm in front of it, beside it: within the 0.1 m filter of each
// other, and inside each other's dilated footprints, so by overlap alone the bar takes the mirror's
// instance, and the merge pass would join a bar instance to the mirror's.
TEST(GlobalPlaneTable, OneFrameKeepsDifferentSurfacesInDifferentInstances) {
  const auto frame_of = [](float same_plane_distance, float planar_rms) {
    LocalObservation mirror = patch(1, 0, 1, 0, 1), bar = patch(2, 1.0f, 1.08f, 0, 1, 0.035f);
    mirror.same_plane_distance = bar.same_plane_distance = same_plane_distance;
    mirror.planar_rms = bar.planar_rms = planar_rms;
    return std::vector<LocalObservation>{mirror, bar};
  };
  {
    GlobalPlaneTable t;
    associate_one(t, patch(1, 0, 1, 0, 1), 0);  // the mirror alone first: instance 1
    // Seen together at ~2 m, where the segmenter's coplanarity tolerance is 1.2 cm: two surfaces.
    const auto both = frame_of(0.012f, 0.012f);
    const FrameAssociation a = t.associate(both, 10);
    EXPECT_EQ(a.local_to_global[1], 1);
    EXPECT_EQ(a.local_to_global[2], 2);
    EXPECT_TRUE(a.merges.empty());
    EXPECT_TRUE(t.seen_apart(1, 2));
    EXPECT_TRUE(t.seen_apart(2, 1));
    // Later the bar alone: its own instance (same overlap, larger IoU), and no merge into the
    // mirror although it lies inside the mirror's dilated footprint.
    LocalObservation bar = both[1];
    bar.local_id = 1;
    const auto scores = t.score(bar, 20);
    ASSERT_EQ(scores.size(), 2u);
    EXPECT_TRUE(scores[0].matched && scores[1].matched);
    EXPECT_EQ(associate_one(t, bar, 20), 2);
    EXPECT_EQ(t.live_ids(), (std::vector<int>{1, 2}));
  }
  {
    // At ~4 m the tolerance (3 σ = 4.8 cm, planarity bound 2 σ_n = 5.2 cm) covers 3.5 cm: one
    // surface, as before the rule.
    GlobalPlaneTable t;
    associate_one(t, patch(1, 0, 1, 0, 1), 0);
    const auto both = frame_of(0.048f, 0.052f);
    const FrameAssociation a = t.associate(both, 10);
    EXPECT_EQ(a.local_to_global[1], 1);
    EXPECT_EQ(a.local_to_global[2], 1);
    EXPECT_FALSE(t.seen_apart(1, 2));
  }
}

// One surface split in two by an occluder: both pieces keep the instance, and seen-apart instances
// stay joinable by an explicit merge's bookkeeping (the lists follow the kept instance).
TEST(GlobalPlaneTable, PiecesOfOneSurfaceShareTheInstance) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 2, 0, 1), 0);
  const LocalObservation pieces[] = {patch(1, 0, 0.9f, 0, 1), patch(2, 1.1f, 2, 0, 1, 0.004f)};
  const FrameAssociation a = t.associate(pieces, 10);
  EXPECT_EQ(a.local_to_global[1], 1);
  EXPECT_EQ(a.local_to_global[2], 1);
  EXPECT_EQ(t.live_ids().size(), 1u);

  GlobalPlaneTable u;
  associate_one(u, patch(1, 0, 1, 0, 1), 0);                       // 1
  associate_one(u, patch(1, 3, 4, 0, 1), 0);                       // 2
  LocalObservation near = patch(1, 5, 6, 0, 1), front = patch(2, 5, 6, 0, 1, 0.05f);
  near.same_plane_distance = front.same_plane_distance = 0.01f;
  const LocalObservation frame[] = {near, front};
  const FrameAssociation b = u.associate(frame, 0);                // 3 and 4, seen apart
  ASSERT_EQ(b.local_to_global[1], 3);
  ASSERT_EQ(b.local_to_global[2], 4);
  EXPECT_TRUE(u.seen_apart(3, 4));
  EXPECT_TRUE(u.merge(2, 3));                                      // 2 absorbs 3 and its list
  EXPECT_TRUE(u.seen_apart(2, 4));
  EXPECT_TRUE(u.seen_apart(4, 3));
  EXPECT_FALSE(u.seen_apart(1, 4));
}

// Two strips of one wall 12 cm wide, 2 m apart, seen at ~4 m (noise σ 1.5 cm, coplanarity
// tolerance 4.4 cm, planarity bound 5.2 cm). Each has in its outer column the edge of something 3 cm
// before the wall (the segmenter takes pixels within 2.5 σ_n of a plane), which tilts its fit by
// ~5°: extrapolated over the 2 m to the other strip, each strip's plane misses it by ~20 cm. The
// plane of their union lies on both: one surface, one instance, nothing recorded as seen apart.
TEST(GlobalPlaneTable, PiecesOfAFarWallWhoseFitsTiltShareTheInstance) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 2.12f, 0, 1), 0);                   // 1: the wall, z = 0
  const auto edge_at = [](float x_edge) { return [=](float x) { return std::abs(x - x_edge) < 0.005f ? 0.03f : 0.0f; }; };
  LocalObservation a = noisy_patch(1, 0.0f, 0.12f, 0, 1, edge_at(0.12f), 0.015f, 1);
  LocalObservation b = noisy_patch(2, 2.0f, 2.12f, 0, 1, edge_at(2.0f), 0.015f, 2);
  for (LocalObservation* o : {&a, &b}) {
    o->same_plane_distance = 0.044f;
    o->planar_rms = 0.052f;
  }
  ASSERT_GT(std::abs(a.plane.signed_distance(b.centroid)), 0.15f);  // the premise: tilted fits
  ASSERT_GT(std::abs(b.plane.signed_distance(a.centroid)), 0.15f);
  const LocalObservation frame[] = {a, b};
  const FrameAssociation f = t.associate(frame, 10);
  EXPECT_EQ(f.local_to_global[1], 1);
  EXPECT_EQ(f.local_to_global[2], 1);
  EXPECT_EQ(f.created, 0);
  EXPECT_EQ(t.live_ids(), (std::vector<int>{1}));
}

// A chair's seat 6 cm over the floor, beside a floor piece of about its size, both with noise σ 5 mm
// (~2.5 m; coplanarity tolerance 1.4 cm, planarity bound 1.7 cm). The plane of their union tilts
// until it passes through both centroids and stays within the planarity bound, so offset and noise
// alone would call them one surface; its residual, 3 times the pieces' own, does not.
TEST(GlobalPlaneTable, ALayerBesideAnotherIsAnotherSurfaceThoughTheirUnionPassesThroughBoth) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0.4f, 1.0f, 0, 0.5f), 0);              // 1: the floor, z = 0
  LocalObservation floor = noisy_patch(1, 0.4f, 1.0f, 0, 0.5f, [](float) { return 0.0f; }, 0.005f, 3);
  LocalObservation seat = noisy_patch(2, 1.02f, 1.52f, 0, 0.5f, [](float) { return 0.06f; }, 0.005f, 4);
  for (LocalObservation* o : {&floor, &seat}) {
    o->same_plane_distance = 0.014f;
    o->planar_rms = 0.017f;
  }
  PlaneMoments both;
  for (const LocalObservation* o : {&floor, &seat})
    for (const Eigen::Vector3f& p : o->points) both.add(p);
  const PlaneFit joint = fit_plane(both);
  ASSERT_LT(std::abs(joint.plane.signed_distance(floor.centroid)), floor.same_plane_distance);  // the premise
  ASSERT_LT(std::abs(joint.plane.signed_distance(seat.centroid)), seat.same_plane_distance);
  ASSERT_LT(std::sqrt(joint.mse), floor.planar_rms);
  const LocalObservation frame[] = {floor, seat};
  const FrameAssociation f = t.associate(frame, 10);
  EXPECT_EQ(f.local_to_global[1], 1);
  EXPECT_EQ(f.local_to_global[2], 2);
  EXPECT_TRUE(t.seen_apart(1, 2));
}

// Among matching instances, those the observation lies on within its noise come first: a piece of
// wall seen where a bar 5 cm in front of it has its instance overlaps the bar's footprint best.
TEST(GlobalPlaneTable, InstancesWithinTheNoiseComeBeforeBetterOverlap) {
  GlobalPlaneTable t;
  associate_one(t, patch(1, 0, 1, 0, 1), 0);                       // 1: wall, z = 0
  LocalObservation wall = patch(1, 0, 1, 0, 1), bar = patch(2, 1.0f, 1.1f, 0, 1, 0.05f);
  wall.same_plane_distance = bar.same_plane_distance = 0.012f;
  const LocalObservation both[] = {wall, bar};
  ASSERT_EQ(t.associate(both, 10).local_to_global[2], 2);          // 2: bar, z = 5 cm
  LocalObservation piece = patch(1, 1.0f, 1.1f, 0, 1);             // wall beside the bar, on z = 0
  piece.same_plane_distance = 0.012f;
  const auto scores = t.score(piece, 20);
  ASSERT_EQ(scores.size(), 2u);
  ASSERT_TRUE(scores[0].matched && scores[1].matched);
  EXPECT_GT(scores[1].overlap, scores[0].overlap);                 // the bar's footprint fits better
  EXPECT_EQ(associate_one(t, piece, 20), 1);                       // but the wall is the surface
}

TEST(GlobalPlaneTable, ObserveTransformsPlanesToWorld) {
  // One local plane: the camera looks down +z at a wall 2 m away; camera 1 m up the world x axis.
  const Intrinsics K{100, 100, 9.5f, 9.5f, 20, 20};
  PlaneSegmentation seg;
  seg.labels = LabelImage(20, 20, 1);
  LocalPlane lp;
  lp.id = 1;
  lp.plane = {Eigen::Vector3f(0, 0, -1), 2.0f};
  lp.centroid = Eigen::Vector3f(0, 0, 2);
  lp.pixels = 400;
  seg.planes = {lp};
  const DepthImage depth(20, 20, 2.0f);
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  T_wc.translation() = Eigen::Vector3f(1, 0, 0);
  GlobalPlaneTable t;
  const auto obs = t.observe(seg, depth, K, T_wc);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_EQ(obs[0].points.size(), 100u);  // stride 2
  EXPECT_NEAR(obs[0].plane.signed_distance(Eigen::Vector3f(5, 3, 2)), 0.0f, 1e-5f);
  EXPECT_NEAR(obs[0].centroid.x(), 1.0f, 1e-5f);
  for (const auto& p : obs[0].points) EXPECT_NEAR(p.z(), 2.0f, 1e-5f);
}

TEST(GlobalPlaneTable, BadParamsThrowNamingTheField) {
  GlobalPlaneParams p;
  p.cell_size = 0;
  try {
    GlobalPlaneTable t(p);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cell_size"), std::string::npos);
  }
}

}  // namespace
}  // namespace rrg
