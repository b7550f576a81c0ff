// The volume's storage: race-free block allocation with growth, streaming to host memory and
// back, changed-block tracking, memory accounting.
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/tsdf_storage_impl.h"
#include "tests/support/parity.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <set>
#include <tuple>

namespace rrg {
namespace {

const Intrinsics kK{150.0f, 150.0f, 79.5f, 59.5f, 160, 120};
using BlockSet = std::set<std::tuple<int, int, int>>;

TsdfParams params(int64_t initial_blocks = 4096) {
  TsdfParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  p.initial_blocks = initial_blocks;
  return p;
}

// The blocks on every pixel's ray within [d − ε, d + ε], one pixel at a time into a std::set.
BlockSet expected_blocks(const DepthImage& depth, const Eigen::Isometry3f& T, const TsdfParams& p) {
  BlockSet out;
  const float to_block = 1.0f / (p.voxel_size * kBlockSide), half = 0.5f / kBlockSide;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const float d = depth(x, y);
      if (!(d >= p.min_depth && d <= p.max_depth)) continue;
      const Eigen::Vector3f a = T * kK.unproject(float(x), float(y), d - p.truncation);
      const Eigen::Vector3f b = T * kK.unproject(float(x), float(y), d + p.truncation);
      kernel::for_blocks_on_segment(a * to_block + Eigen::Vector3f::Constant(half),
                                    b * to_block + Eigen::Vector3f::Constant(half),
                                    [&](const Eigen::Vector3i& c) { out.insert({c.x(), c.y(), c.z()}); });
      // Independent check of the traversal: dense samples along the segment land in visited blocks.
      if ((x + y) % 7 == 0)
        for (int k = 0; k <= 200; ++k) {
          const Eigen::Vector3f q = (a + (b - a) * (float(k) / 200.0f)) * to_block + Eigen::Vector3f::Constant(half);
          EXPECT_TRUE(out.count({int(std::floor(q.x())), int(std::floor(q.y())), int(std::floor(q.z()))}));
        }
    }
  return out;
}

BlockSet allocated(const TsdfVolume& v) {
  BlockSet out;
  for (const auto& c : v.block_coords()) out.insert({c.x(), c.y(), c.z()});
  return out;
}

TEST(TsdfStorage, AllocationFindsExactlyTheBlocksOnTheRaysWithoutLosingAny) {
  // Every pixel of a fronto-parallel wall hits the same few blocks: maximal contention on the hash.
  // A table of 2 slots to start with forces several grow-and-retry passes within the first frame.
  const DepthImage wall(kK.width, kK.height, 1.0f);
  const test::Scene sphere = test::sphere_scene({0, 0, 0}, 0.3f);
  const auto T0 = Eigen::Isometry3f::Identity();
  const auto T1 = test::look_at({0.2f, -0.1f, -0.9f}, {0, 0, 0});
  const DepthImage ball = sphere.render_depth(kK, T1);
  BlockSet want = expected_blocks(wall, T0, params(1));
  const BlockSet after_first = want;
  for (const auto& b : expected_blocks(ball, T1, params(1))) want.insert(b);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume v(params(1), device);
    const ColorImage grey(kK.width, kK.height, Color(0.5f, 0.5f, 0.5f));
    const auto c = DeviceImage<Color>::from_host(grey, device);
    EXPECT_EQ(integrate(v, DeviceImage<float>::from_host(wall, device), c, kK, T0), int64_t(after_first.size()));
    EXPECT_EQ(allocated(v), after_first);
    EXPECT_EQ(v.num_blocks(), int64_t(after_first.size()));  // no duplicates
    integrate(v, DeviceImage<float>::from_host(ball, device), c, kK, T1);
    EXPECT_EQ(allocated(v), want);
    EXPECT_EQ(v.num_blocks(), int64_t(want.size()));
    EXPECT_GE(v.hash_capacity(), 2 * v.num_blocks());  // load factor kept <= 1/2
  }
}

// A sphere fused from around it on `device`, with its voxels and a novel view's raycast depth.
struct FusedSphere {
  TsdfVolume volume;
  std::vector<float> voxels;
  DepthImage depth;
};
const Eigen::Vector3f kSphereCentre(0, 0, 0);
const Eigen::Isometry3f kNovel = test::look_at({0.5f, 0.4f, -0.6f}, kSphereCentre);
FusedSphere fused_sphere(const Device& device) {
  TsdfVolume v(params(), device);
  test::fuse_scene(v, test::sphere_scene(kSphereCentre, 0.25f), kK, test::cameras_around(kSphereCentre, 0.9f));
  std::vector<float> voxels = test::flatten_voxels(v);
  DepthImage depth = raycast(v, kK, kNovel).depth.to_host();
  return {std::move(v), std::move(voxels), std::move(depth)};
}

TEST(TsdfStorage, StreamingOutAndBackInIsExact) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    FusedSphere fs = fused_sphere(device);
    TsdfVolume& v = fs.volume;
    const auto& before = fs.voxels;
    const auto& depth_before = fs.depth;
    const int64_t total = v.num_blocks();
    const MemoryUsage m0 = v.memory();
    EXPECT_EQ(m0.host_bytes, 0u);

    const int64_t moved = v.stream_out({0.3f, 0, 0}, 0.3f);  // keeps the +x half resident
    EXPECT_GT(moved, 0);
    EXPECT_LT(moved, total);
    EXPECT_EQ(v.num_blocks() + v.num_host_blocks(), total);
    EXPECT_GE(v.memory().host_bytes, size_t(moved) * kBlockVoxels * sizeof(Voxel));
    EXPECT_EQ(test::flatten_voxels(v), before);  // read_all_blocks sees both places
    for (const auto& b : v.block_coords())
      EXPECT_LE((((b.cast<float>() * 8.0f).array() + 3.5f).matrix() * 0.01f - Eigen::Vector3f(0.3f, 0, 0)).norm(), 0.3f);

    EXPECT_EQ(v.stream_in({-0.3f, 0, 0}, 0.2f) + v.stream_in_all(), moved);
    EXPECT_EQ(v.num_host_blocks(), 0);
    EXPECT_EQ(v.num_blocks(), total);
    EXPECT_EQ(test::flatten_voxels(v), before);
    const auto depth_after = raycast(v, kK, kNovel).depth.to_host();
    EXPECT_TRUE(std::equal(depth_after.pixels().begin(), depth_after.pixels().end(), depth_before.pixels().begin()));
  }
}

// shrink_pool gives back the room beyond the resident blocks (never below them) and changes no
// voxel; the pool grows again when blocks come back.
TEST(TsdfStorage, ShrinkingThePoolKeepsTheResidentBlocks) {
  const Eigen::Vector3f c = kSphereCentre;
  const test::Scene scene = test::sphere_scene(c, 0.25f);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    FusedSphere fs = fused_sphere(device);
    TsdfVolume& v = fs.volume;
    const auto& before = fs.voxels;
    const auto& depth_before = fs.depth;
    const int64_t total = v.num_blocks();
    ASSERT_GE(v.pool_capacity(), total);
    v.stream_out({0.3f, 0, 0}, 0.3f);
    const int64_t resident = v.num_blocks();
    const size_t bytes = v.memory().device_bytes;
    v.shrink_pool(0);  // never below the resident blocks
    EXPECT_EQ(v.pool_capacity(), resident);
    EXPECT_LT(v.memory().device_bytes, bytes);
    EXPECT_EQ(test::flatten_voxels(v), before);
    v.shrink_pool(total);  // no growth either
    EXPECT_EQ(v.pool_capacity(), resident);
    EXPECT_EQ(v.stream_in_all(), total - resident);
    EXPECT_GE(v.pool_capacity(), total);
    EXPECT_EQ(test::flatten_voxels(v), before);
    const auto depth_after = raycast(v, kK, kNovel).depth.to_host();
    EXPECT_TRUE(std::equal(depth_after.pixels().begin(), depth_after.pixels().end(), depth_before.pixels().begin()));
    // Fusion after a shrink: new blocks take the zeroed free slots as before.
    v.stream_out({0.3f, 0, 0}, 0.3f);
    v.shrink_pool(0);
    test::fuse_scene(v, scene, kK, test::cameras_around(c, 0.9f));
    TsdfVolume w(params(), device);
    test::fuse_scene(w, scene, kK, test::cameras_around(c, 0.9f));
    test::fuse_scene(w, scene, kK, test::cameras_around(c, 0.9f));
    EXPECT_EQ(test::flatten_voxels(v), test::flatten_voxels(w));
  }
}

// Listed blocks move and nothing else: coordinates never allocated, out of the key range or
// already in the other place are ignored.
TEST(TsdfStorage, StreamingListedBlocksMovesExactlyThose) {
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.25f);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume v(params(), device);
    test::fuse_scene(v, scene, kK, test::cameras_around({0, 0, 0}, 0.9f));
    const auto before = test::flatten_voxels(v);
    const int64_t total = v.num_blocks();
    std::vector<Eigen::Vector3i> picked;
    const auto coords = v.block_coords();
    for (size_t i = 0; i < coords.size(); i += 3) picked.push_back(coords[i]);
    std::vector<Eigen::Vector3i> listed = picked;
    listed.push_back({1000, 1000, 1000});  // never allocated
    listed.push_back({1 << 22, 0, 0});     // outside the key range
    listed.push_back(picked.front());      // twice

    EXPECT_EQ(v.stream_out(listed), int64_t(picked.size()));
    EXPECT_EQ(v.stream_out(listed), 0);  // already out
    EXPECT_EQ(v.num_blocks(), total - int64_t(picked.size()));
    BlockSet out, expected;
    for (const auto& c : v.host_block_coords()) out.insert({c.x(), c.y(), c.z()});
    for (const auto& c : picked) expected.insert({c.x(), c.y(), c.z()});
    EXPECT_EQ(out, expected);
    for (const auto& c : v.block_coords()) EXPECT_FALSE(expected.count({c.x(), c.y(), c.z()}));
    EXPECT_EQ(test::flatten_voxels(v), before);

    const std::vector<Eigen::Vector3i> half(picked.begin(), picked.begin() + long(picked.size() / 2));
    EXPECT_EQ(v.stream_in(half), int64_t(half.size()));
    EXPECT_EQ(v.stream_in(listed), int64_t(picked.size() - half.size()));
    EXPECT_EQ(v.num_host_blocks(), 0);
    EXPECT_EQ(v.num_blocks(), total);
    EXPECT_EQ(test::flatten_voxels(v), before);
  }
}

// Records move between the pool and host memory 1024 blocks at a time (TsdfVolume's staging):
// several thousand blocks out, part of them back, the rest back, and every voxel is where it was.
TEST(TsdfStorage, StreamingMoreBlocksThanOneTransferIsExact) {
  TsdfParams p = params();
  p.voxel_size = 0.004f;
  p.truncation = 0.016f;
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.5f);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume v(p, device);
    test::fuse_scene(v, scene, kK, test::cameras_around({0, 0, 0}, 1.4f));
    const auto before = test::flatten_voxels(v);
    const int64_t total = v.num_blocks();
    const int64_t moved = v.stream_out({0.5f, 0, 0}, 0.6f);  // keeps the +x side
    EXPECT_GT(moved, 3 * 1024);
    EXPECT_GT(v.num_blocks(), 1024);  // the compaction moves blocks too
    EXPECT_EQ(test::flatten_voxels(v), before);
    EXPECT_GT(v.stream_in({-0.3f, 0, 0}, 0.4f), 1024);
    EXPECT_EQ(test::flatten_voxels(v), before);
    v.stream_in_all();
    EXPECT_EQ(v.num_blocks(), total);
    EXPECT_EQ(test::flatten_voxels(v), before);
  }
}

TEST(TsdfStorage, IntegrationBringsStreamedOutBlocksBack) {
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.25f);
  const auto poses = test::cameras_around({0, 0, 0}, 0.9f);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume streamed(params(), device), plain(params(), device);
    test::fuse_scene(streamed, scene, kK, poses);
    test::fuse_scene(plain, scene, kK, poses);
    EXPECT_EQ(streamed.stream_out({10, 10, 10}, 0.1f), plain.num_blocks());
    EXPECT_EQ(streamed.num_blocks(), 0);
    test::fuse_scene(streamed, scene, kK, {poses[0]});
    test::fuse_scene(plain, scene, kK, {poses[0]});
    EXPECT_GT(streamed.num_blocks(), 0);
    EXPECT_GT(streamed.num_host_blocks(), 0);  // blocks the last frame did not touch stay out
    EXPECT_EQ(test::flatten_voxels(streamed), test::flatten_voxels(plain));
  }
}

// Streaming out frees pool slots that still held voxels; a block allocated later into such a slot
// must start empty (the volume keeps free slots zero, and allocation writes no voxel).
TEST(TsdfStorage, ABlockAllocatedIntoAFreedSlotStartsEmpty) {
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.25f);
  const DepthImage wall(kK.width, kK.height, 1.0f);
  Eigen::Isometry3f far = Eigen::Isometry3f::Identity();
  far.translation() = Eigen::Vector3f(0, 0, 10);  // the wall at z = 11 m, far from the sphere's blocks
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const ColorImage grey(kK.width, kK.height, Color(0.5f, 0.5f, 0.5f));
    const auto c = DeviceImage<Color>::from_host(grey, device);
    const auto d = DeviceImage<float>::from_host(wall, device);
    TsdfVolume reused(params(), device), fresh(params(), device);
    test::fuse_scene(reused, scene, kK, test::cameras_around({0, 0, 0}, 0.9f));
    const int64_t sphere_blocks = reused.num_blocks();
    EXPECT_EQ(reused.stream_out({0, 0, 0}, -1.0f), sphere_blocks);  // every slot freed
    integrate(reused, d, c, kK, far);
    integrate(fresh, d, c, kK, far);
    ASSERT_EQ(reused.num_blocks(), fresh.num_blocks());
    ASSERT_GT(fresh.num_blocks(), 0);
    // The wall's first sphere_blocks blocks went into freed slots (the pool is filled from slot 0).
    for (const auto& b : fresh.block_coords()) {
      const auto got = reused.read_block(b), want = fresh.read_block(b);
      ASSERT_TRUE(got && want);
      ASSERT_EQ(got->voxels.size(), want->voxels.size());
      for (size_t i = 0; i < want->voxels.size(); ++i)
        ASSERT_EQ(std::memcmp(&got->voxels[i], &want->voxels[i], sizeof(Voxel)), 0) << "voxel " << i;
    }
  }
}

TEST(TsdfStorage, ChangedBlocksAreThoseFusedSinceAVersion) {
  TsdfVolume v(params(), Device::cpu());
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.25f);
  const auto poses = test::cameras_around({0, 0, 0}, 0.9f);
  test::fuse_scene(v, scene, kK, {poses[0]});  // camera at −x
  const uint64_t v1 = v.version();
  EXPECT_EQ(v1, 1u);
  const auto first = allocated(v);
  test::fuse_scene(v, scene, kK, {poses[1]});  // camera at +x
  const auto changed = v.changed_blocks(v1);
  EXPECT_FALSE(changed.empty());
  EXPECT_LT(changed.size(), size_t(v.num_blocks()));
  EXPECT_EQ(v.changed_blocks(0).size(), size_t(v.num_blocks()));
  EXPECT_TRUE(v.changed_blocks(v.version()).empty());
  const TriangleMesh part = extract_mesh(v, changed), whole = extract_mesh(v);
  EXPECT_GT(part.triangles.size(), 0u);
  EXPECT_LT(part.triangles.size(), whole.triangles.size());
  for (const auto& p : part.vertices) ASSERT_GT(p.x(), -0.05f);  // the side the second camera saw

  // Streamed out, a changed block is still listed (after the resident ones), with its version.
  const Eigen::Vector3f far_side(-1.0f, 0.0f, 0.0f);  // only blocks on the +x side go out
  const auto all = [](const Eigen::Vector3i&) { return true; };
  EXPECT_TRUE(v.host_blocks_where(all).empty());
  const int64_t out = v.stream_out(far_side, 1.0f);
  ASSERT_GT(out, 0);
  ASSERT_GT(v.num_blocks(), 0);
  EXPECT_EQ(v.host_blocks_where(all), v.host_block_coords());
  EXPECT_EQ(int64_t(v.host_blocks_where(all).size()), out);
  const auto upper = v.host_blocks_where([](const Eigen::Vector3i& c) { return c.y() >= 0; });
  EXPECT_GT(upper.size(), 0u);
  EXPECT_LT(int64_t(upper.size()), out);
  for (const auto& c : upper) EXPECT_GE(c.y(), 0);
  auto sorted = [](std::vector<Eigen::Vector3i> c) {
    std::sort(c.begin(), c.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
      return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
    });
    return c;
  };
  EXPECT_EQ(sorted(v.changed_blocks(v1)), sorted(changed));
  EXPECT_EQ(v.changed_blocks(0).size(), size_t(v.num_blocks() + v.num_host_blocks()));
  EXPECT_TRUE(v.changed_blocks(v.version()).empty());
  const auto listed = v.changed_blocks(0);
  const auto host = v.host_block_coords();
  EXPECT_TRUE(std::equal(host.begin(), host.end(), listed.end() - std::ptrdiff_t(host.size())))
      << "the streamed-out blocks come last, sorted";
}

}  // namespace
}  // namespace rrg
