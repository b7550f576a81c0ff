// Preprocessing (core/tracking/preprocess.h): bilateral filter, depth pyramid, per-level maps.
#include "core/tracking/preprocess.h"
#include "core/tracking/preprocess_device.h"
#include "tests/support/parity.h"
#include "tests/tracking/box_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace rrg {
namespace {

DepthImage image_of(int w, int h, std::initializer_list<float> values) {
  DepthImage d(w, h);
  size_t i = 0;
  for (float v : values) d[i++] = v;
  return d;
}

TEST(Preprocess, DownsampleAveragesBlocksAndSkipsDiscontinuities) {
  // 4x2 -> 2x1. Left block: 1.0, 1.02, 1.04, 0 (invalid) -> mean of the three valid = 1.02.
  // Right block: 2.0, 3.0 (beyond 3σ_d = 0.09 of the first), 2.06, 2.0 -> mean(2.0, 2.06, 2.0) = 2.02.
  const DepthImage d = image_of(4, 2, {1.0f, 1.02f, 2.0f, 3.0f, 1.04f, 0.0f, 2.06f, 2.0f});
  const Image<float> out = downsample_depth(DeviceImage<float>::from_host(d, Device::cpu()), 0.03f).to_host();
  ASSERT_EQ(out.width(), 2);
  ASSERT_EQ(out.height(), 1);
  EXPECT_NEAR(out(0, 0), 1.02f, 1e-6f);
  EXPECT_NEAR(out(1, 0), 2.02f, 1e-6f);
}

TEST(Preprocess, BilateralKeepsPlanesAndEdgesAndInvalids) {
  // A step from 1 m to 2 m: σ_d = 3 cm means the sides never mix; constant regions stay constant.
  DepthImage d(12, 8, 1.0f);
  for (int y = 0; y < 8; ++y)
    for (int x = 6; x < 12; ++x) d(x, y) = 2.0f;
  d(3, 3) = 0.0f;
  const Image<float> out = bilateral_filter_depth(DeviceImage<float>::from_host(d, Device::cpu()), 3, 4.5f, 0.03f).to_host();
  EXPECT_FLOAT_EQ(out(5, 4), 1.0f);
  EXPECT_FLOAT_EQ(out(6, 4), 2.0f);
  EXPECT_EQ(out(3, 3), 0.0f);
  EXPECT_THROW(bilateral_filter_depth(DeviceImage<float>::from_host(d, Device::cpu()), 0, 4.5f, 0.03f),
               std::invalid_argument);
}

TEST(Preprocess, BilateralSmoothsNoiseTowardsTheMean) {
  // Alternating ±5 mm around 1 m: the filtered centre is much closer to 1 m.
  DepthImage d(9, 9);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) d(x, y) = 1.0f + ((x + y) % 2 ? 0.005f : -0.005f);
  const Image<float> out = bilateral_filter_depth(DeviceImage<float>::from_host(d, Device::cpu()), 3, 4.5f, 0.03f).to_host();
  EXPECT_LT(std::abs(out(4, 4) - 1.0f), 0.001f);
}

// The CPU filters a row at a time, tap by tap (preprocess_impl.h); bilateral_at, which CUDA runs
// per pixel, is the reference: the same floats bit for bit, with holes, NaN, edges, image borders
// and a radius wider than the image's height.
TEST(Preprocess, BilateralRowsEqualThePerPixelFilterBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const int radius : {1, 3, 6}) {
    DepthImage d(41, 5);
    for (int y = 0; y < d.height(); ++y)
      for (int x = 0; x < d.width(); ++x) {
        const float r = u(rng);
        d(x, y) = r < 0.1f ? 0.0f : (r < 0.12f ? std::nanf("") : (x < 20 ? 1.0f : 2.5f) + 0.02f * u(rng));
      }
    const Image<float> out =
        bilateral_filter_depth(DeviceImage<float>::from_host(d, Device::cpu()), radius, 4.5f, 0.03f).to_host();
    const float inv_2ss = 0.5f / (4.5f * 4.5f), inv_2sd = 0.5f / (0.03f * 0.03f);
    const ImageView<const float> view{d.data(), d.width(), d.height()};
    int differ = 0, filtered = 0;
    for (int y = 0; y < d.height(); ++y)
      for (int x = 0; x < d.width(); ++x) {
        const float ref = kernel::bilateral_at(view, x, y, radius, inv_2ss, inv_2sd);
        differ += std::memcmp(&ref, &out(x, y), sizeof(float)) == 0 ? 0 : 1;
        filtered += ref > 0.0f ? 1 : 0;
      }
    EXPECT_EQ(differ, 0) << "radius " << radius;
    EXPECT_GT(filtered, 150);
  }
}

TEST(Preprocess, PyramidLevelsHaveHalvedIntrinsicsAndConsistentVertices) {
  const Intrinsics K = test::test_intrinsics(161, 121);  // odd sizes round up
  const auto box = test::render_box(K, test::look_at({0, 0, 0}, {2, 1, 0.5f}));
  PreprocessParams p;
  p.bilateral = false;
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(box.depth, Device::cpu()), K, p);
  ASSERT_EQ(pyr.levels.size(), 3u);
  EXPECT_EQ(pyr.levels[1].depth.width(), 81);
  EXPECT_EQ(pyr.levels[2].depth.height(), 31);
  EXPECT_FLOAT_EQ(pyr.levels[1].K.fx, K.fx / 2);
  EXPECT_FLOAT_EQ(pyr.levels[1].K.cx, (K.cx + 0.5f) / 2 - 0.5f);
  // A level-1 pixel's vertex lies on the same surface as the level-0 pixels it averages: its
  // reprojection into level 0 lands between them.
  const auto V1 = pyr.levels[1].maps.vertices.to_host();
  const Eigen::Vector3f v = V1(20, 15);
  ASSERT_GT(v.z(), 0.0f);
  const Eigen::Vector2f uv = K.project(v);
  EXPECT_NEAR(uv.x(), 40.5f, 0.05f);
  EXPECT_NEAR(uv.y(), 30.5f, 0.05f);
  EXPECT_THROW(build_pyramid(DeviceImage<float>::from_host(box.depth, Device::cpu()), test::test_intrinsics(160, 120), p),
               std::invalid_argument);
}

// V_k^l are the sensor's, N_k^l the filter's (docs/tracking.md "Positions from the sensor, normals
// from the filter"): level 0's depth is the input bit for bit, its filtered depth is the bilateral
// filter's, and every level's maps are those of (depth, filtered); without the filter both come from
// the depth.
template <class T>
std::vector<T> host_pixels(const DeviceImage<T>& image) {
  const Image<T> host = image.to_host();
  return {host.pixels().begin(), host.pixels().end()};
}
template <class T>
std::vector<T> host_pixels(const Image<T>& image) {
  return {image.pixels().begin(), image.pixels().end()};
}

TEST(Preprocess, PyramidPositionsAreTheSensorsAndNormalsTheFilters) {
  const Intrinsics K = test::test_intrinsics(96, 72);
  auto box = test::render_box(K, test::look_at({0, 0, 0}, {2, 1, 0.5f}));
  for (int i = 0; i < int(box.depth.size()); i += 7) box.depth[size_t(i)] += 0.004f * float(i % 5) - 0.008f;
  const auto raw = DeviceImage<float>::from_host(box.depth, Device::cpu());
  const PreprocessParams p;
  ASSERT_TRUE(p.bilateral);
  const FramePyramid pyr = build_pyramid(raw, K, p);
  EXPECT_EQ(host_pixels(pyr.levels[0].depth), host_pixels(box.depth));
  const auto filtered = bilateral_filter_depth(raw, p.bilateral_radius, p.sigma_space_px, p.sigma_depth_m);
  EXPECT_EQ(host_pixels(pyr.levels[0].filtered), host_pixels(filtered));
  EXPECT_NE(host_pixels(filtered), host_pixels(box.depth));  // the noise is smoothed: the two differ
  for (size_t l = 0; l < pyr.levels.size(); ++l) {
    const PyramidLevel& level = pyr.levels[l];
    if (l > 0) {
      EXPECT_EQ(host_pixels(level.depth), host_pixels(downsample_depth(pyr.levels[l - 1].depth, p.sigma_depth_m)));
      EXPECT_EQ(host_pixels(level.filtered),
                host_pixels(downsample_depth(pyr.levels[l - 1].filtered, p.sigma_depth_m)));
    }
    const VertexNormalMaps own = compute_vertex_normal_maps(level.depth, level.K);
    const VertexNormalMaps smooth = compute_vertex_normal_maps(level.filtered, level.K);
    EXPECT_EQ(host_pixels(level.maps.vertices), host_pixels(own.vertices)) << "level " << l;
    EXPECT_EQ(host_pixels(level.maps.normals), host_pixels(smooth.normals)) << "level " << l;
  }
  PreprocessParams off;
  off.bilateral = false;
  const FramePyramid plain = build_pyramid(raw, K, off);
  EXPECT_EQ(plain.levels[0].filtered.width(), 0);
  EXPECT_EQ(&plain.levels[0].normal_depth(), &plain.levels[0].depth);
  EXPECT_EQ(host_pixels(plain.levels[0].maps.normals), host_pixels(compute_vertex_normal_maps(raw, K).normals));
}

// build_pyramid_into (the tracker's, one pyramid for every frame) gives what a fresh pyramid gives,
// whatever the pyramid held before: another frame, another size, the filter on or off, more levels.
void expect_same_pyramid(const FramePyramid& a, const FramePyramid& b) {
  ASSERT_EQ(a.levels.size(), b.levels.size());
  for (size_t l = 0; l < a.levels.size(); ++l) {
    SCOPED_TRACE("level " + std::to_string(l));
    const PyramidLevel &x = a.levels[l], &y = b.levels[l];
    EXPECT_EQ(x.K.to_string(), y.K.to_string());
    EXPECT_EQ(host_pixels(x.depth), host_pixels(y.depth));
    EXPECT_EQ(x.filtered.width(), y.filtered.width());
    EXPECT_EQ(host_pixels(x.filtered), host_pixels(y.filtered));
    EXPECT_EQ(host_pixels(x.maps.vertices), host_pixels(y.maps.vertices));
    EXPECT_EQ(host_pixels(x.maps.normals), host_pixels(y.maps.normals));
  }
}

TEST(Preprocess, PyramidBuiltInPlaceEqualsAFreshOne) {
  auto frame = [](int w, int h, float yaw) {
    const Intrinsics K = test::test_intrinsics(w, h);
    auto box = test::render_box(K, test::look_at({0, 0, 0}, {2, 1 + yaw, 0.5f}));
    for (int i = 0; i < int(box.depth.size()); i += 7) box.depth[size_t(i)] += 0.004f * float(i % 5) - 0.008f;
    return std::pair{K, DeviceImage<float>::from_host(box.depth, Device::cpu())};
  };
  PreprocessParams on, off, two;
  off.bilateral = false;
  two.levels = 2;
  FramePyramid reused;
  const auto [K0, d0] = frame(96, 72, 0.0f);
  const auto [K1, d1] = frame(96, 72, 0.3f);
  const auto [K2, d2] = frame(64, 48, 0.1f);
  for (const auto& [K, d, p] : {std::tuple{&K0, &d0, &on}, {&K1, &d1, &on}, {&K1, &d1, &off}, {&K0, &d0, &on},
                                {&K2, &d2, &two}, {&K0, &d0, &on}}) {
    build_pyramid_into(reused, *d, *K, *p);
    expect_same_pyramid(reused, build_pyramid(*d, *K, *p));
  }
  // A size mismatch is refused before anything is written.
  const FramePyramid before = build_pyramid(d0, K0, on);
  EXPECT_THROW(build_pyramid_into(reused, d2, K0, on), std::invalid_argument);
  expect_same_pyramid(reused, before);
}

std::vector<float> pyramid_depths(const Device& device) {
  const Intrinsics K = test::test_intrinsics(96, 72);
  auto box = test::render_box(K, test::look_at({0, 0, 0}, {2, 1, 0.5f}));
  for (int i = 0; i < int(box.depth.size()); i += 7) box.depth[size_t(i)] += 0.004f * float(i % 5) - 0.008f;
  const FramePyramid pyr = build_pyramid(DeviceImage<float>::from_host(box.depth, device), K, PreprocessParams{});
  std::vector<float> out;
  for (const PyramidLevel& l : pyr.levels) {
    const auto depth = l.depth.to_host();
    const auto filtered = l.filtered.to_host();
    const auto normals = l.maps.normals.to_host();
    for (float d : depth.pixels()) out.push_back(d);
    for (float d : filtered.pixels()) out.push_back(d);
    for (const auto& n : normals.pixels()) out.push_back(n.x() + 2 * n.y() + 3 * n.z());
  }
  return out;
}

// Tolerance: the bilateral weights use expf, which differs by a few ulps between the host and the
// GPU; normals are cross products of differences of neighbouring vertices and amplify that to
// ~3e-5 (seen on an H100). 1e-4 still catches any wrong pixel (those differ by O(1)).
TEST(Preprocess, PyramidDeviceParity) { test::expect_device_parity<float>(pyramid_depths, 1e-4, 1e-4); }

}  // namespace
}  // namespace rrg
