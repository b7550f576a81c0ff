// The CPU's fusion schedule (tsdf_integrate_cpu.cpp: a row of 8 voxels tested at once) against
// the per-voxel loop CUDA runs, on voxels of every kind: in front of the band, in it, behind it,
// off the image, too far from the pixel's point, at pixels without fusion data; voxels that start
// empty or full (weight at W_max, Welford count saturated), with and without the reflection update.
#include "core/common/depth_maps.h"
#include "core/tsdf/tsdf_integrate_impl.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

namespace rrg {
namespace {

struct Blocks {
  std::vector<uint64_t> keys;
  std::vector<int32_t> active;
  std::vector<TsdfVoxel> geometry;
  std::vector<AttrVoxel> attributes;
  std::vector<uint64_t> versions;
};

// Blocks over the region the camera sees (1 cm voxels: blocks of 8 cm) with random contents.
Blocks random_blocks(uint32_t seed) {
  Blocks b;
  for (int z = 4; z < 30; ++z)
    for (int y = -6; y < 6; ++y)
      for (int x = -9; x < 9; ++x)
        if ((x * 7 + y * 3 + z) % 5 != 0) {  // some holes: not every block is active
          b.active.push_back(int32_t(b.keys.size()));
          b.keys.push_back(block_key(x, y, z));
        }
  const size_t n = b.keys.size() * kBlockVoxels;
  b.geometry.resize(n);
  b.attributes.resize(n);
  b.versions.assign(b.keys.size(), 0);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> w(0, 120), q(-32767, 32767), c(0, 65535), pick(0, 9);
  for (size_t i = 0; i < n; ++i) {
    const int kind = pick(rng);  // empty, at W_max, saturated Welford count, or anything
    b.geometry[i].weight = uint16_t(kind == 0 ? 0 : (kind == 1 ? 100 : w(rng)));
    b.geometry[i].tsdf = int16_t(q(rng));
    AttrVoxel& a = b.attributes[i];
    for (uint16_t& ch : a.rgb) ch = uint16_t(c(rng));
    a.n = uint16_t(kind == 2 ? 65535 : w(rng));
    a.mu = float(c(rng)) / 65535.0f;
    a.m2 = float(c(rng)) / 6553.5f;
    a.r = uint16_t(c(rng));
    a.plane = uint16_t(pick(rng));
  }
  return b;
}

TEST(TsdfIntegrate, RowLanesMatchThePerVoxelLoop) {
  const Intrinsics K{160.0f, 160.0f, 79.5f, 59.5f, 160, 120};
  // a tilted plane behind a sphere, seen slightly rotated: oblique normals, silhouettes, holes
  test::Scene scene = test::sphere_scene(Eigen::Vector3f(0.1f, 0.05f, 1.2f), 0.25f);
  scene.primitives.push_back({test::Primitive::Plane, Eigen::Vector3f(0.3f, -0.2f, -1.0f).normalized(),
                              Eigen::Vector3f(-1.9f, 0, 0)});
  const Eigen::Isometry3f T_wc = Eigen::Translation3f(0.02f, -0.03f, 0.05f) *
                                 Eigen::AngleAxisf(0.1f, Eigen::Vector3f(0.2f, 1.0f, 0.1f).normalized());
  DepthImage depth_h = scene.render_depth(K, T_wc);
  for (int v = 40; v < 50; ++v)
    for (int u = 20; u < 40; ++u) depth_h(u, v) = 0.0f;  // a hole
  const auto depth = DeviceImage<float>::from_host(depth_h, Device::cpu());
  const VertexNormalMaps maps = compute_vertex_normal_maps(depth, K);
  DeviceImage<kernel::FusionPixel> pixels;
  pixels.ensure(K.width, K.height, Device::cpu());
  kernel::fusion_pixels_cpu({depth.view(), maps.normals.view(), K, 0.1f, 10.0f, pixels.view()});

  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  ColorImage color(K.width, K.height);
  Image<int32_t> ids(K.width, K.height);
  Image<uint8_t> mask(K.width, K.height);
  for (size_t i = 0; i < color.size(); ++i) {
    color[i] = Color(u01(rng), u01(rng), u01(rng));
    ids[i] = int32_t(u01(rng) * 6.0f) - 1;  // -1 .. 4: none, remapped, beyond the table
    mask[i] = u01(rng) < 0.5f ? 1 : 0;
  }
  const std::vector<int32_t> remap = {-1, 2, 2, -1};
  const Eigen::Matrix3f R_cw = T_wc.linear().transpose();
  const Eigen::Vector3f t_cw = -(R_cw * T_wc.translation());

  for (const bool reflection : {false, true}) {
    SCOPED_TRACE(reflection ? "identification frame" : "plain frame");
    Blocks lanes = random_blocks(17), ref = random_blocks(17);
    int fused_counts[3] = {0, 0, 0};
    const auto args = [&](Blocks& b) {
      return kernel::IntegrateArgs<Eigen::Vector3f>{
          pixels.view(), ImageView<const Eigen::Vector3f>{color.data(), K.width, K.height}, K, R_cw, t_cw,
          0.01f, TruncationBand{0.015f, 3.0f, DepthNoiseModel{}}, 100, 5,  // ε(d) > ε beyond 1.8 m: the plane
          Span<const int32_t>{b.active.data(), int64_t(b.active.size())},
          Span<const uint64_t>{b.keys.data(), int64_t(b.keys.size())},
          Span<TsdfVoxel>{b.geometry.data(), int64_t(b.geometry.size())},
          Span<AttrVoxel>{b.attributes.data(), int64_t(b.attributes.size())},
          Span<uint64_t>{b.versions.data(), int64_t(b.versions.size())}, 7, reflection,
          0.8f,  // 1 / exposure gain 1.25: both loops scale the Welford input alike
          ImageView<const int32_t>{ids.data(), K.width, K.height},
          ImageView<const uint8_t>{mask.data(), K.width, K.height},
          Span<const int32_t>{remap.data(), int64_t(remap.size())}};
    };
    kernel::integrate_cpu(args(lanes));
    kernel::integrate_per_voxel_cpu(args(ref));
    ASSERT_EQ(std::memcmp(lanes.geometry.data(), ref.geometry.data(), ref.geometry.size() * sizeof(TsdfVoxel)), 0);
    ASSERT_EQ(std::memcmp(lanes.attributes.data(), ref.attributes.data(), ref.attributes.size() * sizeof(AttrVoxel)), 0);
    EXPECT_EQ(lanes.versions, ref.versions);
    // every kind occurred: count the voxels each way changed against the untouched start
    const Blocks start = random_blocks(17);
    for (size_t i = 0; i < ref.geometry.size(); ++i) {
      const bool changed = ref.geometry[i].weight != start.geometry[i].weight ||
                           ref.geometry[i].tsdf != start.geometry[i].tsdf;
      const bool reflected = ref.attributes[i].n != start.attributes[i].n;
      fused_counts[0] += !changed;
      fused_counts[1] += changed && !reflected;
      fused_counts[2] += reflected;
    }
    EXPECT_GT(fused_counts[0], 100000);  // left alone
    EXPECT_GT(fused_counts[1], 10000);   // fused, no reflection update
    if (reflection) EXPECT_GT(fused_counts[2], 1000);  // band voxels on identification frames
    else EXPECT_EQ(fused_counts[2], 0);
  }
}

}  // namespace
}  // namespace rrg
