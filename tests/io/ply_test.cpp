// PLY: binary round trip of every attribute, hand-written ascii with a quad, odd types, errors.
#include "core/io/ply.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

namespace rrg::io {
namespace {

TriangleMesh sample_mesh() {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25f, -3.5f, 1e-3f}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, -1}, {0.6f, 0.8f, 0}};
  m.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5f, 0.2f, 1.0f}};
  m.plane_ids = {0, 3, 3, 70000};
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  return m;
}

TEST(Ply, BinaryRoundTrip) {
  test::TempDir dir("io-ply");
  const TriangleMesh m = sample_mesh();
  write_ply_mesh(dir / "m.ply", m);
  const TriangleMesh b = read_ply_mesh(dir / "m.ply");
  ASSERT_EQ(b.vertices.size(), 4u);
  ASSERT_EQ(b.triangles.size(), 2u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(b.vertices[i], m.vertices[i]);
    EXPECT_EQ(b.normals[i], m.normals[i]);
    EXPECT_EQ(b.plane_ids[i], m.plane_ids[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.colors[i][k], m.colors[i][k], 0.5f / 255.0f + 1e-6f);
  }
  EXPECT_EQ(b.triangles[1], Eigen::Vector3i(1, 3, 2));
  // The file is binary little endian with the documented header and exact size.
  std::ifstream in(dir / "m.ply", std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t body = data.find("end_header\n") + 11;
  EXPECT_NE(data.find("format binary_little_endian 1.0"), std::string::npos);
  EXPECT_EQ(data.size() - body, 4u * (12 + 12 + 3 + 4) + 2u * 13);
  float x;
  std::memcpy(&x, data.data() + body + (12 + 12 + 3 + 4) * 3 + 4, 4);  // vertex 3, y
  EXPECT_EQ(x, -3.5f);
}

TEST(Ply, PositionsOnlyRoundTrip) {
  test::TempDir dir("io-ply");
  TriangleMesh m;
  m.vertices = {{1, 2, 3}, {4, 5, 6}};
  write_ply_mesh(dir / "p.ply", m);
  const TriangleMesh b = read_ply_mesh(dir / "p.ply");
  EXPECT_EQ(b.vertices[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_TRUE(b.colors.empty());
  EXPECT_TRUE(b.normals.empty());
  EXPECT_TRUE(b.triangles.empty());
}

TEST(Ply, AsciiWithQuadAndExtraProperties) {
  test::TempDir dir("io-ply");
  std::ofstream(dir / "q.ply") << "ply\r\nformat ascii 1.0\r\ncomment hand written\r\n"
                                  "element vertex 4\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\n"
                                  "property ushort red\r\nproperty ushort green\r\nproperty ushort blue\r\n"
                                  "property float confidence\r\n"
                                  "element face 1\r\nproperty list int uint vertex_index\r\nproperty uchar flags\r\n"
                                  "element camera 1\r\nproperty float fov\r\nend_header\r\n"
                                  "0 0 0 65535 0 0 0.5\r\n2 0 0 0 65535 0 0.5\r\n2 2 0 0 0 65535 1\r\n"
                                  "0 2 +0.5e1 0 0 0 1\r\n"
                                  "4 0 1 2 3 7\r\n"
                                  "60\r\n";
  const TriangleMesh m = read_ply_mesh(dir / "q.ply");
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices[3], Eigen::Vector3f(0, 2, 5));
  ASSERT_EQ(m.colors.size(), 4u);
  EXPECT_EQ(m.colors[0], Eigen::Vector3f(1, 0, 0));
  EXPECT_EQ(m.colors[2], Eigen::Vector3f(0, 0, 1));
  ASSERT_EQ(m.triangles.size(), 2u);  // the quad, fan-split
  EXPECT_EQ(m.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(m.triangles[1], Eigen::Vector3i(0, 2, 3));
}

TEST(Ply, BinaryWithShortAndCharTypes) {
  test::TempDir dir("io-ply");
  std::string d = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty short x\nproperty char y\n"
                  "property int z\nproperty uchar r\nproperty uchar g\nproperty uchar b\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&d](auto v) { d.append(reinterpret_cast<const char*>(&v), sizeof(v)); };
  put(int16_t(-300)), put(int8_t(-2)), put(int32_t(100000)), put(uint8_t(255)), put(uint8_t(0)), put(uint8_t(51));
  put(int16_t(1)), put(int8_t(2)), put(int32_t(3)), put(uint8_t(0)), put(uint8_t(0)), put(uint8_t(0));
  put(int16_t(4)), put(int8_t(5)), put(int32_t(6)), put(uint8_t(0)), put(uint8_t(0)), put(uint8_t(0));
  put(uint8_t(3)), put(int32_t(2)), put(int32_t(1)), put(int32_t(0));
  std::ofstream(dir / "s.ply", std::ios::binary) << d;
  const TriangleMesh m = read_ply_mesh(dir / "s.ply");
  EXPECT_EQ(m.vertices[0], Eigen::Vector3f(-300, -2, 100000));
  EXPECT_NEAR(m.colors[0].z(), 0.2f, 1e-6f);
  EXPECT_EQ(m.triangles[0], Eigen::Vector3i(2, 1, 0));
  // Cut the file inside the face list: the error names the element.
  std::ofstream(dir / "cut.ply", std::ios::binary) << d.substr(0, d.size() - 3);
  try {
    read_ply_mesh(dir / "cut.ply");
    FAIL() << "truncated file accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cut.ply"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'face'"), std::string::npos) << e.what();
  }
}

TEST(Ply, ErrorsNameTheProblem) {
  test::TempDir dir("io-ply");
  auto expect_msg = [&](const std::string& name, const std::string& text, const std::string& frag) {
    std::ofstream(dir / name) << text;
    try {
      read_ply_mesh(dir / name);
      ADD_FAILURE() << name << " accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(frag), std::string::npos) << e.what();
    }
  };
  expect_msg("obj.ply", "v 1 2 3\n", "not a PLY");
  expect_msg("be.ply", "ply\nformat binary_big_endian 1.0\nelement vertex 0\nend_header\n", "binary_big_endian");
  expect_msg("noxyz.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float u\nend_header\n1\n", "x, y, z");
  expect_msg("range.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
             "indexes vertex 3");
  expect_msg("nan.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                        "property float z\nend_header\n1 2 abc\n", "'abc'");
  expect_msg("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", "'quad'");
  EXPECT_THROW(read_ply_mesh(dir / "missing.ply"), std::runtime_error);
}

TEST(Ply, InvalidMeshIsNotWritten) {
  test::TempDir dir("io-ply");
  TriangleMesh m = sample_mesh();
  m.triangles.push_back({0, 1, 9});
  EXPECT_THROW(write_ply_mesh(dir / "bad.ply", m), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.ply"));
}

}  // namespace
}  // namespace rrg::io
