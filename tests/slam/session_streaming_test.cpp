// A session that streams its TSDF (tsdf.stream_radius) maps, tracks and answers every query as one
// that holds the whole volume, bit for bit, while far fewer blocks stay resident.
#include "tests/slam/session_fixture.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace rrg {
namespace {

class SessionStreamingTest : public test::SynthSessionTest<SessionStreamingTest, 32> {};

void expect_same_mesh(const TriangleMesh& a, const TriangleMesh& b, const char* what) {
  EXPECT_GT(a.triangles.size(), 100u) << what;
  EXPECT_EQ(a.vertices, b.vertices) << what;
  EXPECT_EQ(a.colors, b.colors) << what;
  EXPECT_EQ(a.plane_ids, b.plane_ids) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
}

template <class T>
bool same_pixels(const Image<T>& a, const Image<T>& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::equal(a.pixels().begin(), a.pixels().end(), b.pixels().begin());
}

void expect_same_images(const SessionView& a, const SessionView& b, const char* what) {
  EXPECT_TRUE(same_pixels(a.C, b.C)) << what;
  EXPECT_TRUE(same_pixels(a.C_r, b.C_r)) << what;
  EXPECT_TRUE(same_pixels(a.depth, b.depth)) << what;
  EXPECT_TRUE(same_pixels(a.R, b.R)) << what;
}

TEST_F(SessionStreamingTest, AStreamedSessionIsTheSessionThatHoldsEverything) {
  const auto d = io::open_dataset(root());
  SessionConfig c = base_config(*d);
  c.tracking.mode = TrackingMode::IcpOrbMask;  // the tracking mask's raycasts too
  // Reflection Gaussians early (as snapshot_test.cpp): identification's raycasts every frame.
  c.plane_period = 1;
  c.planes.variance_skip_color_edges = false;
  c.mapping_period = 5;
  c.tsdf.max_depth = 4.0f;
  Session whole(c);
  // Well inside a frame's reach: blocks in view go out after each frame and come back for the
  // next frame's raycasts and fusion, the mapping steps' and identification's.
  c.stream_radius = 0.75f;
  Session streamed(c);
  int64_t most_out = 0;
  for (size_t i = 0; i < 32; ++i) {
    const FrameReport a = whole.process(frame(*d, i, i == 0));
    const FrameReport b = streamed.process(frame(*d, i, i == 0));
    ASSERT_TRUE(a.T_wc.matrix() == b.T_wc.matrix()) << "frame " << i;
    const SessionStatus st = streamed.status();
    most_out = std::max(most_out, st.tsdf_blocks - st.resident_blocks);
  }
  whole.finish();
  streamed.finish();
  const SessionStatus a = whole.status(), b = streamed.status();
  ASSERT_GT(most_out, a.tsdf_blocks / 3) << "too little was streamed out to test anything";
  EXPECT_EQ(a.tsdf_blocks, b.tsdf_blocks);
  EXPECT_EQ(a.resident_blocks, a.tsdf_blocks);
  EXPECT_LT(b.resident_blocks, b.tsdf_blocks);
  EXPECT_GT(b.host_bytes, 0u);
  EXPECT_GT(a.mapping.steps, 1);
  EXPECT_EQ(a.reflective_planes, b.reflective_planes);
  EXPECT_GT(a.mapping.reflection_gaussians, 0);

  EXPECT_EQ(whole.base_gaussians().means, streamed.base_gaussians().means);
  EXPECT_EQ(whole.reflection_gaussians().means, streamed.reflection_gaussians().means);

  // Renders anywhere: where the camera ended, where it started (blocks streamed out long ago).
  const int64_t resident = b.resident_blocks;
  for (const size_t i : {size_t(0), size_t(15), size_t(31)}) {
    const Eigen::Isometry3f T = d->load(i).T_wc_gt->cast<float>();
    expect_same_images(whole.render(c.K, T), streamed.render(c.K, T), "render");
  }
  EXPECT_EQ(streamed.status().resident_blocks, resident) << "a render left blocks resident";
  EXPECT_EQ(streamed.status().tsdf_device_bytes, b.tsdf_device_bytes) << "a render grew the device pool for good";

  // Meshes: whole, changed since a version, the viewer's blocks.
  expect_same_mesh(whole.mesh(), streamed.mesh(), "mesh()");
  expect_same_mesh(whole.mesh(20), streamed.mesh(20), "mesh(20)");
  const Session::ChangedBlocks ca = whole.changed_blocks(0), cb = streamed.changed_blocks(0);
  EXPECT_EQ(ca.volume_version, cb.volume_version);
  ASSERT_EQ(int64_t(cb.blocks.size()), b.tsdf_blocks) << "streamed-out blocks are listed too";
  auto sorted = [](std::vector<Eigen::Vector3i> v) {
    std::sort(v.begin(), v.end(), [](const Eigen::Vector3i& x, const Eigen::Vector3i& y) {
      return std::tie(x.x(), x.y(), x.z()) < std::tie(y.x(), y.y(), y.z());
    });
    return v;
  };
  const std::vector<Eigen::Vector3i> all = sorted(cb.blocks);
  EXPECT_EQ(sorted(ca.blocks), all);
  const std::vector<Eigen::Vector3i> some(all.begin(), all.begin() + std::ptrdiff_t(all.size() / 3));
  expect_same_mesh(whole.mesh_of_blocks(some), streamed.mesh_of_blocks(some), "mesh_of_blocks");
  EXPECT_EQ(streamed.status().resident_blocks, resident) << "a mesh left blocks resident";
  EXPECT_EQ(streamed.status().tsdf_device_bytes, b.tsdf_device_bytes) << "a mesh grew the device pool for good";
}

// Save / Load (the service's snapshots, idle timeouts, drains) keep a streaming session's far
// blocks in host memory: the loaded session's device pool holds what the last frame left resident.
TEST_F(SessionStreamingTest, ALoadedStreamingSessionKeepsItsFarBlocksOnTheHost) {
  const auto d = io::open_dataset(root());
  SessionConfig c = base_config(*d);
  c.mapping_period = 5;
  c.tsdf.max_depth = 4.0f;
  c.stream_radius = 2.5f;  // some blocks stay resident, more go out
  c.tsdf.initial_blocks = 64;  // the pool grows with what stays resident
  const test::TempDir dir("stream-snap");
  Session first(c);
  for (size_t i = 0; i < 16; ++i) first.process(frame(*d, i, i == 0));
  first.save(dir / "s.rrgs");
  const SessionStatus saved = first.status();
  ASSERT_GT(saved.resident_blocks, 0);
  ASSERT_LT(saved.resident_blocks, saved.tsdf_blocks / 2) << "too little was streamed out to test anything";
  const auto loaded = Session::load(dir / "s.rrgs");
  const SessionStatus st = loaded->status();
  EXPECT_EQ(st.tsdf_blocks, saved.tsdf_blocks);
  EXPECT_EQ(st.resident_blocks, saved.resident_blocks);
  EXPECT_EQ(st.host_bytes, saved.host_bytes);
  EXPECT_LE(st.tsdf_device_bytes, saved.tsdf_device_bytes);
  // Its pool holds the resident blocks alone, so reads of the far blocks grow it, and give it back.
  const Eigen::Isometry3f T0 = d->load(0).T_wc_gt->cast<float>();
  expect_same_images(first.render(c.K, T0), loaded->render(c.K, T0), "render at the first pose");
  EXPECT_EQ(loaded->status().tsdf_device_bytes, st.tsdf_device_bytes) << "a render grew the device pool for good";
  expect_same_mesh(first.mesh(), loaded->mesh(), "mesh() after loading");
  EXPECT_EQ(loaded->status().tsdf_device_bytes, st.tsdf_device_bytes) << "a mesh grew the device pool for good";
  EXPECT_EQ(loaded->status().resident_blocks, st.resident_blocks);
  // It goes on as the session that was never saved.
  for (size_t i = 16; i < 32; ++i) {
    const FrameReport a = first.process(frame(*d, i, false));
    const FrameReport b = loaded->process(frame(*d, i, false));
    ASSERT_TRUE(a.T_wc.matrix() == b.T_wc.matrix()) << "frame " << i;
  }
  first.finish();
  loaded->finish();
  EXPECT_EQ(loaded->status().resident_blocks, first.status().resident_blocks);
  expect_same_mesh(first.mesh(), loaded->mesh(), "mesh()");
}

TEST_F(SessionStreamingTest, ANegativeRadiusIsRefused) {
  const auto d = io::open_dataset(root());
  SessionConfig c = base_config(*d);
  c.stream_radius = -1.0f;
  try {
    Session s(c);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tsdf.stream_radius"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rrg
