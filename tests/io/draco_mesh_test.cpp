// Draco meshes: round trips keep the face count and every triangle (matched by position), with
// positions within the documented quantisation bound, colours within half an 8-bit step and plane
// ids exact; bad meshes, options and buffers are refused with std::invalid_argument.
#include "core/io/draco_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

namespace rrg::io {
namespace {

// A wavy (nx x ny) vertex grid over [0, 3] x [0, 2] m, two triangles per cell, colours and plane
// ids varying per vertex, normals of the wave.
TriangleMesh wavy_grid(int nx, int ny) {
  TriangleMesh m;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const float x = 3.0f * i / (nx - 1), y = 2.0f * j / (ny - 1), z = 0.2f * std::sin(3.0f * x) * std::cos(2.0f * y);
      m.vertices.emplace_back(x, y, z);
      m.normals.push_back(Eigen::Vector3f(-0.6f * std::cos(3.0f * x) * std::cos(2.0f * y),
                                          0.4f * std::sin(3.0f * x) * std::sin(2.0f * y), 1.0f)
                              .normalized());
      m.colors.emplace_back(float(i) / (nx - 1), float(j) / (ny - 1), 0.3f);
      m.plane_ids.push_back((i * 7 + j * 3) % 5);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      m.triangles.emplace_back(a, b, d);
      m.triangles.emplace_back(a, d, c);
    }
  return m;
}

// Index of the original vertex nearest to p (brute force; small meshes).
int nearest(const TriangleMesh& m, const Eigen::Vector3f& p) {
  int best = -1;
  float best_d = 1e30f;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const float d = (m.vertices[i] - p).squaredNorm();
    if (d < best_d) best_d = d, best = int(i);
  }
  return best;
}

// A triangle as a rotation-invariant key (orientation kept).
std::array<int, 3> key(int a, int b, int c) {
  std::array<int, 3> t{a, b, c};
  std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  return t;
}

void expect_round_trip(const TriangleMesh& in, const DracoOptions& o) {
  const auto bytes = encode_draco(in, o);
  const TriangleMesh out = decode_draco(bytes);
  ASSERT_NO_THROW(out.validate());
  ASSERT_EQ(out.triangles.size(), in.triangles.size());
  ASSERT_EQ(out.colors.size(), out.vertices.size());
  ASSERT_EQ(out.normals.size(), out.vertices.size());
  ASSERT_EQ(out.plane_ids.size(), out.vertices.size());
  // Documented bound: extent / (2 (2^bits - 1)) per coordinate, extent = largest bbox side.
  Eigen::Vector3f lo = in.vertices[0], hi = in.vertices[0];
  for (const auto& v : in.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const float extent = (hi - lo).maxCoeff();
  const float bound = extent / (2.0f * float((1 << o.position_bits) - 1)) * 1.001f + 1e-6f;
  std::vector<int> match(out.vertices.size());
  float max_err = 0, min_dot = 1;
  for (size_t i = 0; i < out.vertices.size(); ++i) {
    const int k = match[i] = nearest(in, out.vertices[i]);
    ASSERT_LE((out.vertices[i] - in.vertices[size_t(k)]).cwiseAbs().maxCoeff(), bound) << "vertex " << i;
    EXPECT_LE((out.colors[i] - in.colors[size_t(k)]).cwiseAbs().maxCoeff(), 0.5f / 255.0f + 1e-6f) << "vertex " << i;
    EXPECT_EQ(out.plane_ids[i], in.plane_ids[size_t(k)]) << "vertex " << i;
    EXPECT_GT(out.normals[i].dot(in.normals[size_t(k)]), 0.999f) << "vertex " << i;
    max_err = std::max(max_err, (out.vertices[i] - in.vertices[size_t(k)]).cwiseAbs().maxCoeff());
    min_dot = std::min(min_dot, out.normals[i].normalized().dot(in.normals[size_t(k)]));
  }
  std::printf("draco speed %d, %d position bits: %zu B for %zu vertices / %zu faces; position error %.3g m "
              "(bound %.3g), normal error %.3f deg\n", o.speed, o.position_bits, bytes.size(), in.vertices.size(),
              in.triangles.size(), max_err, bound, std::acos(std::min(1.0f, min_dot)) * 180.0 / 3.14159265);
  std::multiset<std::array<int, 3>> want, got;
  for (const auto& t : in.triangles) want.insert(key(t.x(), t.y(), t.z()));
  for (const auto& t : out.triangles) got.insert(key(match[size_t(t.x())], match[size_t(t.y())], match[size_t(t.z())]));
  EXPECT_TRUE(want == got) << "the decoded triangles are not the encoded ones";
}

TEST(DracoMesh, RoundTripEdgebreakerAndSequential) {
  const TriangleMesh m = wavy_grid(23, 17);
  for (const int speed : {0, 5, 10}) {
    SCOPED_TRACE("speed " + std::to_string(speed));
    DracoOptions o;
    o.speed = speed;
    expect_round_trip(m, o);
  }
  DracoOptions coarse;
  coarse.position_bits = 11;  // 3 m / 2047 / 2 = 0.73 mm, still distinct grid vertices
  expect_round_trip(m, coarse);
}

TEST(DracoMesh, CompressesBelowRawSize) {
  const TriangleMesh m = wavy_grid(40, 40);
  const auto bytes = encode_draco(m);
  const size_t raw = m.vertices.size() * (12 + 12 + 3 + 4) + m.triangles.size() * 12;
  EXPECT_LT(bytes.size(), raw / 4);
}

TEST(DracoMesh, GeometryOnlyMeshHasNoAttributes) {
  TriangleMesh m = wavy_grid(5, 4);
  m.colors.clear();
  m.normals.clear();
  m.plane_ids.clear();
  const TriangleMesh out = decode_draco(encode_draco(m));
  EXPECT_EQ(out.triangles.size(), m.triangles.size());
  EXPECT_TRUE(out.colors.empty());
  EXPECT_TRUE(out.normals.empty());
  EXPECT_TRUE(out.plane_ids.empty());
}

TEST(DracoMesh, NonManifoldAndDegenerateFacesKeepTheFaceCount) {
  // A fan of three triangles on one edge (non-manifold), a zero-area sliver and a face with a
  // repeated vertex (marching cubes can emit both).
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0.5f, 0, 0}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {0, 5, 1}, {2, 2, 4}};
  for (const int speed : {0, 5, 10}) {
    DracoOptions o;
    o.speed = speed;
    const TriangleMesh out = decode_draco(encode_draco(m, o));
    EXPECT_EQ(out.triangles.size(), m.triangles.size()) << "speed " << speed;
  }
}

TEST(DracoMesh, BadInputsAreRefused) {
  TriangleMesh m = wavy_grid(4, 4);
  DracoOptions o;
  o.position_bits = 0;
  EXPECT_THROW(encode_draco(m, o), std::invalid_argument);
  o = {};
  o.color_bits = 10;
  EXPECT_THROW(encode_draco(m, o), std::invalid_argument);
  EXPECT_THROW(encode_draco(TriangleMesh{}), std::invalid_argument);
  TriangleMesh bad = m;
  bad.triangles.emplace_back(0, 1, 99);
  EXPECT_THROW(encode_draco(bad), std::invalid_argument);

  EXPECT_THROW(decode_draco({}), std::invalid_argument);
  const std::vector<uint8_t> junk{'n', 'o', 't', ' ', 'd', 'r', 'a', 'c', 'o'};
  EXPECT_THROW(decode_draco(junk), std::invalid_argument);
  // Truncated buffers: Draco itself is not fuzzed here; every cut of a small mesh must be refused.
  const auto bytes = encode_draco(m);
  for (size_t len = 0; len < bytes.size(); ++len)
    EXPECT_THROW(decode_draco(std::span<const uint8_t>(bytes.data(), len)), std::invalid_argument) << "cut at " << len;
}

}  // namespace
}  // namespace rrg::io
