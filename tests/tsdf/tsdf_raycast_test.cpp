// The fast raycast (range image, block skipping, TSDF-sized steps, secant refinement) against a
// brute-force reference that samples the same trilinear TSDF every 0.05 voxel from min_depth and
// bisects the first +/− crossing: same hit/miss away from silhouettes, depth within 0.05 voxel.
#include "core/common/memory.h"
#include "core/tsdf/tsdf_range_device.h"
#include "core/tsdf/tsdf_raycast.h"
#include "core/tsdf/tsdf_raycast_device.h"
#include "core/tsdf/tsdf_sample_device.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rrg {
namespace {

const Intrinsics kSmallK{75.0f, 75.0f, 39.5f, 29.5f, 80, 60};

// z-depth of the first crossing from a valid sample f > 0 to a valid sample f <= 0 at consecutive
// steps of 0.05 voxel (in metres along the ray), bisected to 1e-6 voxel; 0 for none.
float reference_depth(const TsdfVolume& volume, const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
  const kernel::VolumeView view{volume.hash_view(), volume.geometry(), volume.attributes(), volume.params().voxel_size};
  kernel::BlockCache cache;
  const float s = volume.params().voxel_size, dz = 0.05f * s / d.norm();
  bool have_prev = false;
  float f_prev = 0;
  for (float z = volume.params().min_depth; z < volume.params().max_depth; z += dz) {
    float f;
    if (!kernel::sample_tsdf(view, o + z * d, cache, f)) {
      have_prev = false;
      continue;
    }
    if (have_prev && f_prev > 0 && f <= 0) {
      float a = z - dz, b = z;
      for (int it = 0; it < 40 && b - a > 1e-6f * s; ++it) {
        const float m = 0.5f * (a + b);
        float fm;
        if (!kernel::sample_tsdf(view, o + m * d, cache, fm)) break;
        (fm > 0 ? a : b) = m;
      }
      return 0.5f * (a + b);
    }
    have_prev = true;
    f_prev = f;
  }
  return 0.0f;
}

struct Comparison {
  int compared = 0, hits = 0, hit_mismatch = 0;
  float worst_depth = 0;  // metres, over pixels both hit
};

// Pixels whose 3x3 neighbourhood in the reference has a miss/hit change or a depth step larger
// than `step` are silhouettes and left out.
Comparison compare_with_reference(const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc) {
  const RaycastResult fast = raycast(volume, K, T_wc);
  const DepthImage depth = fast.depth.to_host();
  DepthImage ref(K.width, K.height, 0.0f);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x)
      ref(x, y) = reference_depth(volume, T_wc.translation(), T_wc.linear() * K.unproject(float(x), float(y), 1.0f));
  const float step = 4.0f * volume.params().voxel_size;
  Comparison c;
  for (int y = 1; y + 1 < K.height; ++y)
    for (int x = 1; x + 1 < K.width; ++x) {
      bool silhouette = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const float n = ref(x + dx, y + dy);
          silhouette |= (n > 0) != (ref(x, y) > 0) || std::abs(n - ref(x, y)) > step;
        }
      if (silhouette) continue;
      ++c.compared;
      const bool hit_ref = ref(x, y) > 0, hit_fast = depth(x, y) > 0;
      c.hits += hit_ref;
      if (hit_ref != hit_fast) {
        ++c.hit_mismatch;
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): reference " << ref(x, y) << " fast " << depth(x, y);
      } else if (hit_ref) {
        c.worst_depth = std::max(c.worst_depth, std::abs(ref(x, y) - depth(x, y)));
      }
    }
  return c;
}

TsdfParams params_1cm() {
  TsdfParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  p.max_depth = 2.5f;  // keeps the brute-force march short
  return p;
}

TEST(TsdfRaycast, FastMarchAgreesWithADenseReferenceMarch) {
  const test::Scene scene{{{test::Primitive::Sphere, {0, 0, 0}, {0.2f, 0, 0}},
                           {test::Primitive::Box, {0.25f, 0.1f, 0.1f}, {0.1f, 0.12f, 0.08f}}}};
  TsdfVolume volume(params_1cm(), Device::cpu());
  test::fuse_scene(volume, scene, kSmallK, test::cameras_around({0.05f, 0, 0}, 0.9f));
  const std::vector<Eigen::Isometry3f> views = {
      test::look_at({0.4f, -0.3f, -0.7f}, {0, 0, 0}),        // novel, whole scene in view
      test::look_at({0.0f, 0.0f, -0.9f}, {0.05f, 0, 0}),     // a fused view
      test::look_at({-0.25f, 0.05f, -0.12f}, {0.2f, 0, 0}),  // inside the allocated band: blocks
                                                              // straddle the image plane
  };
  for (size_t v = 0; v < views.size(); ++v) {
    SCOPED_TRACE("view " + std::to_string(v));
    const Comparison c = compare_with_reference(volume, kSmallK, views[v]);
    EXPECT_GT(c.compared, kSmallK.width * kSmallK.height / 2);
    EXPECT_GT(c.hits, 300);
    EXPECT_EQ(c.hit_mismatch, 0);
    EXPECT_LT(c.worst_depth, 0.05f * volume.params().voxel_size);
  }
}

// The CPU raycast keeps several rays in flight per work item, one march_step of each in turn, with
// one block cache for all of them. Each ray must still end where it ends marching alone: the same
// hit or miss and the same depth, bit for bit.
TEST(TsdfRaycast, InterleavedMarchStepsGiveEachRayItsOwnHit) {
  const test::Scene scene{{{test::Primitive::Sphere, {0, 0, 0}, {0.2f, 0, 0}},
                           {test::Primitive::Box, {0.25f, 0.1f, 0.1f}, {0.1f, 0.12f, 0.08f}}}};
  TsdfVolume volume(params_1cm(), Device::cpu());
  test::fuse_scene(volume, scene, kSmallK, test::cameras_around({0.05f, 0, 0}, 0.9f));
  const kernel::VolumeView view{volume.hash_view(), volume.geometry(), volume.attributes(), volume.params().voxel_size};
  const Eigen::Isometry3f T = test::look_at({0.4f, -0.3f, -0.7f}, {0, 0, 0});
  const float eps = volume.params().truncation, z0 = volume.params().min_depth, z1 = volume.params().max_depth;
  std::vector<Eigen::Vector3f> dirs;
  for (int v = 0; v < kSmallK.height; ++v)
    for (int u = 0; u < kSmallK.width; ++u) dirs.push_back(T.linear() * kSmallK.unproject(float(u), float(v), 1.0f));
  std::vector<kernel::RayHit> alone(dirs.size());
  for (size_t r = 0; r < dirs.size(); ++r) {
    kernel::BlockCache cache;
    alone[r] = kernel::march(view, T.translation(), dirs[r], eps, z0, z1, cache);
  }
  constexpr int kLanes = 4;
  kernel::BlockCache shared;
  int hits = 0;
  for (size_t first = 0; first < dirs.size(); first += kLanes) {
    kernel::MarchState lane[kLanes];
    bool done[kLanes] = {};
    const int n = int(std::min<size_t>(kLanes, dirs.size() - first));
    for (int l = 0; l < n; ++l) kernel::march_begin(lane[l], view, T.translation(), dirs[first + size_t(l)], eps, z0, z1);
    for (int left = n; left > 0;)
      for (int l = 0; l < n; ++l)
        if (!done[l] && kernel::march_step(view, lane[l], shared)) done[l] = true, --left;
    for (int l = 0; l < n; ++l) {
      const kernel::RayHit& a = alone[first + size_t(l)];
      const kernel::RayHit& b = lane[l].hit;
      ASSERT_EQ(a.hit, b.hit) << "ray " << first + size_t(l);
      if (!a.hit) continue;
      ++hits;
      EXPECT_EQ(a.z, b.z) << "ray " << first + size_t(l);
    }
  }
  EXPECT_GT(hits, 300);
}

// A view from far away (every block near the far end of the range) and from inside a sphere shell
// (every ray starts inside allocated space) both still agree.
TEST(TsdfRaycast, FastMarchAgreesFromFarAndFromInside) {
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.3f);
  TsdfVolume volume(params_1cm(), Device::cpu());
  test::fuse_scene(volume, scene, kSmallK, test::cameras_around({0, 0, 0}, 1.0f));
  for (const auto& T : {test::look_at({0.3f, 0.2f, -2.2f}, {0, 0, 0}), test::look_at({0.0f, 0.0f, -0.05f}, {0, 0, 1})}) {
    const Comparison c = compare_with_reference(volume, kSmallK, T);
    EXPECT_EQ(c.hit_mismatch, 0);
    EXPECT_LT(c.worst_depth, 0.05f * volume.params().voxel_size);
  }
}

// The range image of boxes (here whole blocks) that straddle the camera's plane (a wall or floor
// beside the camera):
// conservative, since every point of a block at a depth the march samples (>= min_depth) that
// projects into the image lies in a covered tile whose [near, far] holds its depth; and tight, since
// it covers the part of the image the clipped block can reach, not the whole image (it did: every
// tile's near bound fell to min_depth). Camera at the origin looking along +z, 2 cm voxels
// (16 cm blocks), the volume shifted 12 cm along the view so each block spans z from -4 to 12 cm.
TEST(TsdfRaycast, RangeOfABlockAcrossTheCameraPlaneIsConservativeAndTight) {
  const float voxel = 0.02f, side = 8 * voxel, min_depth = 0.1f, max_depth = 5.0f;
  const Eigen::Matrix3f R_cw = Eigen::Matrix3f::Identity();
  const Eigen::Vector3f t_cw(0.0f, 0.0f, 0.12f);
  const int tiles_x = (kSmallK.width + kernel::kRangeTile - 1) / kernel::kRangeTile;
  const int tiles_y = (kSmallK.height + kernel::kRangeTile - 1) / kernel::kRangeTile;
  // block (-1, -1, -1): x, y in [-16, 0] cm, the upper left of the view; block (2, 0, -1): x in
  // [32, 48] cm, beyond the image's right edge at every depth it has in front of min_depth
  for (const Eigen::Vector3i b : {Eigen::Vector3i(-1, -1, -1), Eigen::Vector3i(2, 0, -1)}) {
    SCOPED_TRACE("block " + std::to_string(b.x()) + " " + std::to_string(b.y()) + " " + std::to_string(b.z()));
    std::vector<int32_t> near_neg(size_t(tiles_x * tiles_y)), far(size_t(tiles_x * tiles_y));
    const kernel::RangeImage range{{near_neg.data(), int64_t(near_neg.size())}, {far.data(), int64_t(far.size())},
                                   tiles_x, tiles_y};
    for (int64_t t = 0; t < int64_t(near_neg.size()); ++t) kernel::range_clear(range, t);
    kernel::range_splat_box(range, b.cast<float>() * side, Eigen::Vector3f::Constant(side), kSmallK, R_cw, t_cw,
                            min_depth, max_depth);
    int covered = 0;
    for (int y = 0; y < kSmallK.height; y += kernel::kRangeTile)
      for (int x = 0; x < kSmallK.width; x += kernel::kRangeTile) {
        float n, f;
        kernel::range_at(range, x, y, n, f);
        covered += n <= f;
      }
    // every point of the box in front of min_depth that the image sees: covered, depth within
    int seen = 0;
    const Eigen::Vector3f lo = b.cast<float>() * side;
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; j <= 40; ++j)
        for (int k = 0; k <= 40; ++k) {
          const Eigen::Vector3f q = R_cw * (lo + side * Eigen::Vector3f(float(i), float(j), float(k)) / 40.0f) + t_cw;
          if (q.z() < min_depth) continue;
          const Eigen::Vector2f uv = kSmallK.project(q);
          const int x = int(std::floor(uv.x() + 0.5f)), y = int(std::floor(uv.y() + 0.5f));
          if (x < 0 || y < 0 || x >= kSmallK.width || y >= kSmallK.height) continue;
          ++seen;
          float n, f;
          kernel::range_at(range, x, y, n, f);
          ASSERT_LE(n, q.z() + 1e-6f) << "pixel " << x << " " << y;
          ASSERT_GE(f, q.z() - 1e-6f) << "pixel " << x << " " << y;
        }
    if (b.x() < 0) {
      EXPECT_GT(seen, 1000);
      EXPECT_GT(covered, 0);
      EXPECT_LT(covered, tiles_x * tiles_y * 3 / 4);  // about the upper-left quarter, not all
    } else {
      EXPECT_EQ(seen, 0);
      EXPECT_EQ(covered, 0);
    }
  }
}

// crossing_box: the hull of [v − 1, v + 1] over the observed voxels with d ≤ 0, by hand; a voxel
// with d ≤ 0 that was never observed (weight 0) does not count, nor does a block of free space.
TEST(TsdfRaycast, CrossingBoxIsTheHullOfTheObservedVoxelsAtOrBehindTheSurface) {
  std::vector<TsdfVoxel> geometry(2 * kBlockVoxels);
  for (auto& v : geometry) v = {voxel_codec::encode_tsdf(0.7f), 3};  // observed free space
  TsdfVoxel* b1 = geometry.data() + kBlockVoxels;
  b1[local_index(2, 3, 4)] = {voxel_codec::encode_tsdf(-0.2f), 1};
  b1[local_index(6, 1, 7)] = {voxel_codec::encode_tsdf(0.0f), 2};
  b1[local_index(7, 7, 0)] = {voxel_codec::encode_tsdf(-0.9f), 0};  // never observed
  geometry[local_index(0, 0, 0)] = {voxel_codec::encode_tsdf(-0.5f), 0};
  const Span<const TsdfVoxel> view{geometry.data(), int64_t(geometry.size())};
  int lo[3], hi[3];
  EXPECT_FALSE(kernel::crossing_box(view, 0, lo, hi));
  ASSERT_TRUE(kernel::crossing_box(view, 1, lo, hi));
  EXPECT_EQ(Eigen::Vector3i(lo[0], lo[1], lo[2]), Eigen::Vector3i(1, 0, 3));
  EXPECT_EQ(Eigen::Vector3i(hi[0], hi[1], hi[2]), Eigen::Vector3i(6, 3, 7));
  // The volume's codes give the same boxes back; a code never computed is every voxel's box.
  int dlo[3], dhi[3];
  EXPECT_EQ(kernel::encode_crossing_box(view, 0), kernel::kNoCrossing);
  EXPECT_FALSE(kernel::decode_crossing_box(kernel::kNoCrossing, dlo, dhi));
  ASSERT_TRUE(kernel::decode_crossing_box(kernel::encode_crossing_box(view, 1), dlo, dhi));
  EXPECT_EQ(Eigen::Vector3i(dlo[0], dlo[1], dlo[2]), Eigen::Vector3i(1, 0, 3));
  EXPECT_EQ(Eigen::Vector3i(dhi[0], dhi[1], dhi[2]), Eigen::Vector3i(6, 3, 7));
  b1[local_index(0, 0, 0)] = {voxel_codec::encode_tsdf(-0.1f), 1};  // a corner voxel: the box leaves the block
  ASSERT_TRUE(kernel::crossing_box(view, 1, lo, hi));
  EXPECT_EQ(Eigen::Vector3i(lo[0], lo[1], lo[2]), Eigen::Vector3i(-1, -1, -1));
  EXPECT_EQ(Eigen::Vector3i(hi[0], hi[1], hi[2]), Eigen::Vector3i(6, 3, 7));
  ASSERT_TRUE(kernel::decode_crossing_box(kernel::encode_crossing_box(view, 1), dlo, dhi));
  EXPECT_EQ(Eigen::Vector3i(dlo[0], dlo[1], dlo[2]), Eigen::Vector3i(-1, -1, -1));
  EXPECT_EQ(Eigen::Vector3i(dhi[0], dhi[1], dhi[2]), Eigen::Vector3i(6, 3, 7));
  ASSERT_TRUE(kernel::decode_crossing_box(kernel::kBoxUnknown, dlo, dhi));
  EXPECT_EQ(Eigen::Vector3i(dlo[0], dlo[1], dlo[2]), Eigen::Vector3i(-1, -1, -1));
  EXPECT_EQ(Eigen::Vector3i(dhi[0], dhi[1], dhi[2]), Eigen::Vector3i(7, 7, 7));
}

// Every resident block's code in crossing_boxes() is its box from its voxels now (worked out on
// the host, so on CUDA this is also the kernel's parity check): after fusion, after streaming some
// blocks out (the pool compacts), after fusing frames that bring some back, after streaming the
// rest in, and in a volume built from the blocks by insert_blocks (loading).
void expect_boxes_current(const TsdfVolume& volume) {
  const Span<const uint32_t> on_device = volume.crossing_boxes();
  std::vector<uint32_t> codes(size_t(on_device.size));
  mem::copy(codes.data(), Device::cpu(), on_device.data, volume.device(), codes.size() * sizeof(uint32_t));
  int with_box = 0, checked = 0;
  const std::vector<Eigen::Vector3i> coords = volume.block_coords();
  for (size_t b = 0; b < coords.size(); ++b) {
    const std::optional<BlockData> data = volume.read_block(coords[b]);
    ASSERT_TRUE(data);
    std::vector<TsdfVoxel> g(kBlockVoxels);
    for (int i = 0; i < kBlockVoxels; ++i) g[size_t(i)] = voxel_geometry(data->voxels[size_t(i)]);
    const uint32_t fresh = kernel::encode_crossing_box({g.data(), int64_t(g.size())}, 0);
    ASSERT_EQ(codes[b], fresh) << "block " << b;
    with_box += fresh != kernel::kNoCrossing;
    ++checked;
  }
  EXPECT_GT(checked, 50);
  EXPECT_GT(with_box, 10);
  EXPECT_LT(with_box, checked);
}

void expect_boxes_current_through_streaming(const Device& device) {
  const test::Scene scene{{{test::Primitive::Sphere, {0, 0, 0}, {0.2f, 0, 0}},
                           {test::Primitive::Box, {0.25f, 0.1f, 0.1f}, {0.1f, 0.12f, 0.08f}}}};
  const std::vector<Eigen::Isometry3f> cameras = test::cameras_around({0.05f, 0, 0}, 0.9f);
  TsdfVolume volume(params_1cm(), device);
  test::fuse_scene(volume, scene, kSmallK, {cameras.begin(), cameras.begin() + 6});
  {
    SCOPED_TRACE("fused");
    expect_boxes_current(volume);
  }
  ASSERT_GT(volume.stream_out({0.2f, 0.0f, 0.0f}, 0.2f), 0);
  {
    SCOPED_TRACE("streamed out");
    expect_boxes_current(volume);
  }
  test::fuse_scene(volume, scene, kSmallK, {cameras.begin() + 6, cameras.end()});
  {
    SCOPED_TRACE("fused again");
    expect_boxes_current(volume);
  }
  volume.stream_in_all();
  {
    SCOPED_TRACE("streamed in");
    expect_boxes_current(volume);
  }
  TsdfVolume loaded(params_1cm(), device);
  loaded.insert_blocks(volume.read_all_blocks());
  SCOPED_TRACE("inserted");
  expect_boxes_current(loaded);
}

TEST(TsdfRaycast, CrossingBoxesStayCurrentThroughFusionStreamingAndLoading) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    expect_boxes_current_through_streaming(device);
  }
}

// The range image of the raycast (every resident block's crossing box) holds every sample a march
// can end on: each valid trilinear sample with f ≤ 0 on a pixel's ray, taken every 0.1 voxel, lies
// in a block's crossing box and within its tile's [near, far]. And from a view of the whole scene
// it is tighter than whole blocks: every covered tile's near bound is more than a voxel farther,
// and a tenth fewer tiles are covered.
TEST(TsdfRaycast, RangeOfCrossingBoxesHoldsEverySampleAtOrBehindTheSurface) {
  const test::Scene scene{{{test::Primitive::Sphere, {0, 0, 0}, {0.2f, 0, 0}},
                           {test::Primitive::Box, {0.25f, 0.1f, 0.1f}, {0.1f, 0.12f, 0.08f}}}};
  TsdfVolume volume(params_1cm(), Device::cpu());
  test::fuse_scene(volume, scene, kSmallK, test::cameras_around({0.05f, 0, 0}, 0.9f));
  const TsdfParams& p = volume.params();
  const kernel::VolumeView view{volume.hash_view(), volume.geometry(), volume.attributes(), p.voxel_size};
  const Span<const uint64_t> keys = volume.block_keys();
  const int tiles_x = (kSmallK.width + kernel::kRangeTile - 1) / kernel::kRangeTile;
  const int tiles_y = (kSmallK.height + kernel::kRangeTile - 1) / kernel::kRangeTile;
  // A novel view of the whole scene 0.9 m away, and one 8 cm from the sphere, where boxes straddle
  // the camera's plane (there whole blocks and crossing boxes both reach min_depth in every tile).
  for (const auto& [T, tight] : {std::pair{test::look_at({0.4f, -0.3f, -0.7f}, {0, 0, 0}), true},
                                 std::pair{test::look_at({-0.25f, 0.05f, -0.12f}, {0.2f, 0, 0}), false}}) {
    const Eigen::Matrix3f R_cw = T.linear().transpose();
    const Eigen::Vector3f t_cw = -(R_cw * T.translation());
    std::vector<int32_t> near_neg(size_t(tiles_x * tiles_y)), far(near_neg.size());
    std::vector<int32_t> block_near_neg(near_neg.size()), block_far(near_neg.size());
    const kernel::RangeImage range{{near_neg.data(), int64_t(near_neg.size())}, {far.data(), int64_t(far.size())},
                                   tiles_x, tiles_y};
    const kernel::RangeImage blocks{{block_near_neg.data(), int64_t(near_neg.size())},
                                    {block_far.data(), int64_t(near_neg.size())}, tiles_x, tiles_y};
    for (int64_t t = 0; t < int64_t(near_neg.size()); ++t) {
      kernel::range_clear(range, t);
      kernel::range_clear(blocks, t);
    }
    const float side = float(kBlockSide) * p.voxel_size;
    for (int64_t b = 0; b < keys.size; ++b) {
      kernel::range_splat_block(range, volume.crossing_boxes()[b], keys[b], p.voxel_size, kSmallK, R_cw, t_cw,
                                p.min_depth, p.max_depth);
      kernel::range_splat_box(blocks, (block_coord(keys[b]) * int(kBlockSide)).cast<float>() * p.voxel_size,
                              Eigen::Vector3f::Constant(side), kSmallK, R_cw, t_cw, p.min_depth, p.max_depth);
    }
    // p lies in the crossing box of one of the blocks around it (boxes reach a voxel beyond their block)
    const auto in_a_box = [&](const Eigen::Vector3f& pt) {
      const Eigen::Vector3f q = pt / p.voxel_size;
      const Eigen::Vector3i g(int(std::floor(q.x())), int(std::floor(q.y())), int(std::floor(q.z())));
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i b(block_of(g.x()) + dx, block_of(g.y()) + dy, block_of(g.z()) + dz);
            const int32_t i = kernel::hash_find(volume.hash_view(), block_key(b.x(), b.y(), b.z()));
            int lo[3], hi[3];
            if (i < 0 || !kernel::crossing_box(volume.geometry(), i, lo, hi)) continue;
            const Eigen::Vector3f r = q - (b * int(kBlockSide)).cast<float>();
            if (r.x() >= float(lo[0]) && r.x() <= float(hi[0] + 1) && r.y() >= float(lo[1]) &&
                r.y() <= float(hi[1] + 1) && r.z() >= float(lo[2]) && r.z() <= float(hi[2] + 1))
              return true;
          }
      return false;
    };
    kernel::BlockCache cache;
    int negative = 0;
    for (int y = 0; y < kSmallK.height; ++y)
      for (int x = 0; x < kSmallK.width; ++x) {
        const Eigen::Vector3f d = T.linear() * kSmallK.unproject(float(x), float(y), 1.0f);
        float near, far_z;
        kernel::range_at(range, x, y, near, far_z);
        for (float z = p.min_depth; z < p.max_depth; z += 0.1f * p.voxel_size / d.norm()) {
          float f;
          if (!kernel::sample_tsdf(view, T.translation() + z * d, cache, f) || f > 0.0f) continue;
          ++negative;
          ASSERT_TRUE(in_a_box(T.translation() + z * d)) << "pixel " << x << " " << y << " z " << z;
          ASSERT_LE(near, z) << "pixel " << x << " " << y;
          ASSERT_GE(far_z, z) << "pixel " << x << " " << y;
        }
      }
    EXPECT_GT(negative, 10000);
    int covered = 0, covered_by_blocks = 0, farther = 0;
    for (int y = 0; y < kSmallK.height; y += kernel::kRangeTile)
      for (int x = 0; x < kSmallK.width; x += kernel::kRangeTile) {
        float n, f, bn, bf;
        kernel::range_at(range, x, y, n, f);
        kernel::range_at(blocks, x, y, bn, bf);
        covered += n <= f;
        covered_by_blocks += bn <= bf;
        farther += n <= f && n > bn + p.voxel_size;
      }
    if (!tight) continue;
    EXPECT_LT(covered, covered_by_blocks * 9 / 10);
    EXPECT_EQ(farther, covered);
  }
}

// RaycastOutputs: leaving out the colour, the reflection maps or V*, N* changes nothing in the maps
// that are computed, and the maps left out are empty.
void expect_outputs_independent(const Device& device) {
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.3f);
  TsdfVolume volume(params_1cm(), device);
  test::fuse_scene(volume, scene, kSmallK, test::cameras_around({0, 0, 0}, 1.0f));
  const Eigen::Isometry3f T = test::look_at({0.3f, 0.2f, -1.2f}, {0, 0, 0});
  const RaycastResult all = raycast(volume, kSmallK, T);
  const RaycastResult geometry = raycast(volume, kSmallK, T, {}, RaycastOutputs::geometry());
  const RaycastResult color = raycast(volume, kSmallK, T, {}, {.color = true, .reflection = false});
  const RaycastResult refl = raycast(volume, kSmallK, T, {}, {.color = false, .reflection = true});
  const RaycastResult flat = raycast(volume, kSmallK, T, {}, {.color = true, .reflection = true, .normals = false});
  const auto same = [](const auto& a, const auto& b) {
    const auto ha = a.to_host(), hb = b.to_host();
    return ha.same_size(hb) && std::equal(ha.data(), ha.data() + ha.size(), hb.data());
  };
  const DepthImage depth = all.depth.to_host();
  EXPECT_GT(std::count_if(depth.data(), depth.data() + depth.size(), [](float d) { return d > 0; }), 1000);
  for (const RaycastResult* r : {&geometry, &color, &refl}) {
    EXPECT_TRUE(same(r->depth, all.depth));
    EXPECT_TRUE(same(r->vertices, all.vertices));
    EXPECT_TRUE(same(r->normals, all.normals));
  }
  EXPECT_TRUE(same(color.colors, all.colors));
  EXPECT_TRUE(same(refl.color_variance, all.color_variance));
  EXPECT_TRUE(same(refl.plane_ids, all.plane_ids));
  EXPECT_TRUE(same(refl.reflection, all.reflection));
  EXPECT_TRUE(same(refl.reflection_mask, all.reflection_mask));
  // D_t, C_t and the four reflection maps of r equal those of the all-outputs raycast.
  const auto expect_attributes_of_all = [&](const RaycastResult& r) {
    EXPECT_TRUE(same(r.depth, all.depth));
    EXPECT_TRUE(same(r.colors, all.colors));
    EXPECT_TRUE(same(r.color_variance, all.color_variance));
    EXPECT_TRUE(same(r.plane_ids, all.plane_ids));
    EXPECT_TRUE(same(r.reflection, all.reflection));
    EXPECT_TRUE(same(r.reflection_mask, all.reflection_mask));
  };
  // Without V*, N*: every other map as with them; those two empty.
  expect_attributes_of_all(flat);
  EXPECT_EQ(flat.vertices.width() * flat.vertices.height(), 0);
  EXPECT_EQ(flat.normals.width() * flat.normals.height(), 0);
  EXPECT_EQ(all.normals.width(), kSmallK.width);
  EXPECT_EQ(all.colors.width(), kSmallK.width);
  for (const RaycastResult* r : {&geometry, &refl}) EXPECT_EQ(r->colors.width() * r->colors.height(), 0);
  for (const RaycastResult* r : {&geometry, &color}) {
    EXPECT_EQ(r->color_variance.width() * r->color_variance.height(), 0);
    EXPECT_EQ(r->plane_ids.width() * r->plane_ids.height(), 0);
    EXPECT_EQ(r->reflection.width() * r->reflection.height(), 0);
    EXPECT_EQ(r->reflection_mask.width() * r->reflection_mask.height(), 0);
  }
  // raycast_into a result that holds another view's maps (of other sizes too) gives the same maps.
  RaycastResult reused;
  const Intrinsics half{kSmallK.fx / 2, kSmallK.fy / 2, kSmallK.cx / 2, kSmallK.cy / 2, kSmallK.width / 2, kSmallK.height / 2};
  raycast_into(reused, volume, half, test::look_at({-0.4f, 0.1f, -1.0f}, {0, 0, 0}));
  raycast_into(reused, volume, kSmallK, test::look_at({-0.4f, 0.1f, -1.0f}, {0, 0, 0}));
  raycast_into(reused, volume, kSmallK, T, {}, RaycastOutputs::geometry());
  EXPECT_TRUE(same(reused.depth, geometry.depth));
  EXPECT_TRUE(same(reused.vertices, geometry.vertices));
  EXPECT_TRUE(same(reused.normals, geometry.normals));
  EXPECT_EQ(reused.colors.width() * reused.colors.height(), 0);
  EXPECT_EQ(reused.color_variance.width() * reused.color_variance.height(), 0);
  raycast_into(reused, volume, kSmallK, T, {}, {.color = true, .reflection = true, .normals = false});
  EXPECT_EQ(reused.normals.width() * reused.normals.height(), 0);
  raycast_into(reused, volume, kSmallK, T);
  expect_attributes_of_all(reused);
  EXPECT_TRUE(same(reused.vertices, all.vertices));
  EXPECT_TRUE(same(reused.normals, all.normals));
}

// On every device (the kernel branches on the flags; raycast_into reuses device buffers).
TEST(TsdfRaycast, OutputsLeftOutAreEmptyAndTheOthersUnchanged) {
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    expect_outputs_independent(device);
  }
}

}  // namespace
}  // namespace rrg
