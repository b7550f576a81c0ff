// Vertex and normal maps from depth (paper §4.1.1) against analytic planes, on every device.
#include "core/common/depth_maps.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

namespace rrg {
namespace {

const Intrinsics kK{100.0f, 110.0f, 31.5f, 23.5f, 64, 48};

// Depth of the plane n . p = d seen by a pinhole camera: z = d / (n . K^-1 [u v 1]).
DepthImage plane_depth(const Eigen::Vector3f& n, float d) {
  DepthImage depth(kK.width, kK.height);
  for (int y = 0; y < kK.height; ++y)
    for (int x = 0; x < kK.width; ++x) depth(x, y) = d / n.dot(kK.unproject(float(x), float(y), 1.0f));
  return depth;
}

std::vector<float> flatten(const VertexNormalMaps& m) {
  std::vector<float> out;
  for (const auto* img : {&m.vertices, &m.normals}) {
    const auto host = img->to_host();  // named: a temporary's pixels() would dangle in the loop
    for (const auto& v : host.pixels()) out.insert(out.end(), {v.x(), v.y(), v.z()});
  }
  return out;
}

TEST(DepthMaps, FrontoParallelPlane) {
  const DepthImage depth(kK.width, kK.height, 2.0f);
  const auto maps = compute_vertex_normal_maps(DeviceImage<float>::from_host(depth, Device::cpu()), kK);
  const auto V = maps.vertices.to_host(), N = maps.normals.to_host();
  EXPECT_NEAR(V(0, 0).x(), (0 - 31.5f) * 2.0f / 100.0f, 1e-6);
  EXPECT_NEAR(V(10, 40).y(), (40 - 23.5f) * 2.0f / 110.0f, 1e-6);
  EXPECT_FLOAT_EQ(V(5, 5).z(), 2.0f);
  EXPECT_TRUE(N(0, 10).isZero());  // border
  for (int y = 1; y < kK.height - 1; ++y)
    for (int x = 1; x < kK.width - 1; ++x) ASSERT_LT((N(x, y) - Eigen::Vector3f(0, 0, -1)).norm(), 1e-5);
}

TEST(DepthMaps, TiltedPlaneNormalIsTheAnalyticOneOnEveryDevice) {
  const Eigen::Vector3f n = Eigen::Vector3f(0.3f, -0.2f, 1.0f).normalized();
  const DepthImage depth = plane_depth(n, 1.5f);
  test::expect_device_parity<float>(
      [&](const Device& device) {
        const auto maps = compute_vertex_normal_maps(DeviceImage<float>::from_host(depth, device), kK);
        const auto N = maps.normals.to_host();
        for (int y = 1; y < kK.height - 1; ++y)
          for (int x = 1; x < kK.width - 1; ++x) EXPECT_LT((N(x, y) + n).norm(), 1e-4) << x << "," << y;
        return flatten(maps);
      },
      1e-5, 1e-5);
}

TEST(DepthMaps, InvalidDepthInvalidatesItsNeighbours) {
  DepthImage depth(kK.width, kK.height, 1.0f);
  depth(20, 20) = 0.0f;
  const auto maps = compute_vertex_normal_maps(DeviceImage<float>::from_host(depth, Device::cpu()), kK);
  const auto V = maps.vertices.to_host(), N = maps.normals.to_host();
  EXPECT_TRUE(V(20, 20).isZero());
  for (auto [x, y] : {std::pair{20, 20}, {19, 20}, {21, 20}, {20, 19}, {20, 21}}) EXPECT_TRUE(N(x, y).isZero());
  EXPECT_FALSE(N(22, 20).isZero());
}

// The sensor's positions with another depth's normals (the tracker's bilateral-filtered D_k): V is
// depth's bit for bit, N is the normal depth's, and a pixel without depth has neither.
TEST(DepthMaps, VerticesFromTheDepthNormalsFromTheNormalDepth) {
  const Eigen::Vector3f n = Eigen::Vector3f(0.3f, -0.2f, 1.0f).normalized();
  const DepthImage tilted = plane_depth(n, 1.5f);
  DepthImage flat(kK.width, kK.height, 2.0f);
  flat(30, 20) = 0.0f;
  test::expect_device_parity<float>(
      [&](const Device& device) {
        const auto maps = compute_vertex_normal_maps(DeviceImage<float>::from_host(flat, device),
                                                     DeviceImage<float>::from_host(tilted, device), kK);
        const auto own = compute_vertex_normal_maps(DeviceImage<float>::from_host(flat, device), kK);
        const auto V = maps.vertices.to_host(), N = maps.normals.to_host(), V_own = own.vertices.to_host();
        for (int y = 1; y < kK.height - 1; ++y)
          for (int x = 1; x < kK.width - 1; ++x) {
            EXPECT_EQ(V(x, y), V_own(x, y)) << x << "," << y;
            if (x == 30 && y == 20) {
              EXPECT_TRUE(V(x, y).isZero());
              EXPECT_TRUE(N(x, y).isZero());  // the normal depth has a normal here, the depth no point
            } else {
              EXPECT_LT((N(x, y) + n).norm(), 1e-4) << x << "," << y;
            }
          }
        return flatten(maps);
      },
      1e-5, 1e-5);
  const DepthImage small(10, 10, 1.0f);
  try {
    compute_vertex_normal_maps(DeviceImage<float>::from_host(flat, Device::cpu()),
                               DeviceImage<float>::from_host(small, Device::cpu()), kK);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("normals' depth is 10x10"), std::string::npos) << e.what();
  }
}

TEST(DepthMaps, SizeMismatchNamesBothSizes) {
  const DepthImage depth(10, 10, 1.0f);
  try {
    compute_vertex_normal_maps(DeviceImage<float>::from_host(depth, Device::cpu()), kK);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("10x10"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rrg
