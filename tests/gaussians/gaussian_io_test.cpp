// 3DGS PLY (exact round trip, header layout, plane ids + plane JSON) and SPZ v3 (round trip within
// its quantisation, gzip framing, coordinate conversion, corrupt input).
#include "core/gaussians/gaussian_ply.h"
#include "core/gaussians/spz.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <random>

namespace rrg {
namespace {

GaussianHost random_gaussians(size_t n, int degree, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  GaussianHost g(degree);
  g.resize(n);
  for (size_t i = 0; i < n; ++i) {
    g.means[i] = Eigen::Vector3f(u(rng), u(rng), u(rng)) * 5.0f;
    g.log_scales[i] = Eigen::Vector3f(u(rng), u(rng), u(rng)) * 2.0f - Eigen::Vector3f::Constant(4.0f);
    g.quats[i] = Eigen::Vector4f(u(rng), u(rng), u(rng), u(rng));
    g.logit_opacities[i] = u(rng) * 4.0f;
    for (int k = 0; k < g.sh_coeffs(); ++k)
      g.sh[i * g.sh_coeffs() + k] = Eigen::Vector3f(u(rng), u(rng), u(rng)) * (k == 0 ? 1.5f : 0.9f);
    g.plane_ids[i] = int32_t(i % 3);
  }
  return g;
}

TEST(GaussianPly, HeaderFollowsThe3dgsLayout) {
  const std::string h = gaussian_ply_header(7, 3, false);
  std::string expected = "ply\nformat binary_little_endian 1.0\nelement vertex 7\n";
  for (const char* n : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"})
    expected += std::string("property float ") + n + "\n";
  for (int j = 0; j < 45; ++j) expected += "property float f_rest_" + std::to_string(j) + "\n";
  expected += "property float opacity\n";
  for (int j = 0; j < 3; ++j) expected += "property float scale_" + std::to_string(j) + "\n";
  for (int j = 0; j < 4; ++j) expected += "property float rot_" + std::to_string(j) + "\n";
  EXPECT_EQ(h, expected + "end_header\n");
  EXPECT_NE(gaussian_ply_header(1, 0, true).find("property float rot_3\nproperty int plane_id\nend_header\n"),
            std::string::npos);
  EXPECT_EQ(gaussian_ply_header(1, 0, false).find("f_rest"), std::string::npos);
}

TEST(GaussianPly, RoundTripIsExactForEveryDegree) {
  test::TempDir dir;
  for (int degree = 0; degree <= 3; ++degree) {
    const GaussianHost g = random_gaussians(37, degree, 10 + degree);
    const auto path = dir.path() / ("g" + std::to_string(degree) + ".ply");
    write_gaussian_ply(path, g, degree % 2 == 1);
    const GaussianHost r = read_gaussian_ply(path);
    ASSERT_EQ(r.sh_degree, degree);
    ASSERT_EQ(r.size(), g.size());
    for (size_t i = 0; i < g.size(); ++i) {
      EXPECT_EQ(r.means[i], g.means[i]);
      EXPECT_EQ(r.log_scales[i], g.log_scales[i]);
      EXPECT_EQ(r.quats[i], g.quats[i]);
      EXPECT_EQ(r.logit_opacities[i], g.logit_opacities[i]);
      EXPECT_EQ(r.plane_ids[i], degree % 2 == 1 ? g.plane_ids[i] : 0);
    }
    EXPECT_EQ(r.sh, g.sh);
  }
}

TEST(GaussianPly, FRestIsChannelMajorAs3dgsWritesIt) {
  test::TempDir dir;
  GaussianHost g(1);
  g.resize(1);
  for (int k = 0; k < 4; ++k) g.sh[size_t(k)] = Eigen::Vector3f(10.0f * k, 10.0f * k + 1, 10.0f * k + 2);
  write_gaussian_ply(dir.path() / "one.ply", g);
  std::ifstream in(dir.path() / "one.ply", std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t body = all.find("end_header\n") + 11;
  float f[23];
  std::memcpy(f, all.data() + body, sizeof(f));
  // f_dc = coefficient 0; f_rest_0..2 = channel r of coefficients 1..3, then g, then b
  EXPECT_EQ(f[6], 0.0f);
  EXPECT_EQ(f[7], 1.0f);
  EXPECT_EQ(f[9], 10.0f);
  EXPECT_EQ(f[10], 20.0f);
  EXPECT_EQ(f[11], 30.0f);
  EXPECT_EQ(f[12], 11.0f);
  EXPECT_EQ(f[15], 12.0f);
}

TEST(GaussianPly, ReflectionFileCarriesPlaneIdsAndEquations) {
  test::TempDir dir;
  const GaussianHost g = random_gaussians(5, 0, 3);
  const std::vector<ReflectivePlane> planes = {{1, Eigen::Vector4f(0, 0, 1, -0.75f)}, {2, Eigen::Vector4f(1, 0, 0, 2.5f)}};
  const auto path = dir.path() / "reflection.ply";
  write_reflection_ply(path, g, planes);
  EXPECT_EQ(planes_json_path(path), dir.path() / "reflection.planes.json");
  EXPECT_EQ(read_gaussian_ply(path).plane_ids, g.plane_ids);
  const auto back = read_planes_json(planes_json_path(path));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].id, 2);
  EXPECT_EQ(back[1].plane, planes[1].plane);
  EXPECT_THROW(read_gaussian_ply(dir.path() / "missing.ply"), std::runtime_error);
  std::ofstream(dir.path() / "bad.ply") << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
  EXPECT_THROW(read_gaussian_ply(dir.path() / "bad.ply"), std::runtime_error);
}

void expect_within_quantisation(const GaussianHost& g, const GaussianHost& r) {
  ASSERT_EQ(r.size(), g.size());
  ASSERT_EQ(r.sh_degree, g.sh_degree);
  const int K = g.sh_coeffs();
  for (size_t i = 0; i < g.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(r.means[i][c], g.means[i][c], 0.5f / 4096 + 1e-6f);                // 12 fractional bits
      EXPECT_NEAR(r.log_scales[i][c], g.log_scales[i][c], 0.5f / 16 + 1e-5f);         // 1/16 steps
      EXPECT_NEAR(r.sh[i * K][c], g.sh[i * K][c], 0.5f / (0.15f * 255) + 1e-5f);      // colour byte
    }
    const auto sig = [](float x) { return 1.0f / (1.0f + std::exp(-x)); };
    EXPECT_NEAR(sig(r.logit_opacities[i]), sig(g.logit_opacities[i]), 0.5f / 255 + 1e-5f);
    const Eigen::Vector4f a = g.quats[i].normalized(), b = r.quats[i].normalized();
    EXPECT_GT(std::abs(a.dot(b)), 1.0f - 2e-5f);  // 9-bit smallest-three: ~1e-3 per component
    for (int k = 1; k < K; ++k)
      for (int c = 0; c < 3; ++c)  // buckets of 8 (degree 1) or 16 codes of 1/128, plus rounding
        EXPECT_NEAR(r.sh[i * K + k][c], g.sh[i * K + k][c], (k < 4 ? 4.5f : 8.5f) / 128.0f);
  }
}

TEST(Spz, RoundTripWithinQuantisation) {
  for (int degree = 0; degree <= 3; ++degree) {
    const GaussianHost g = random_gaussians(200, degree, 20 + degree);
    const std::vector<uint8_t> bytes = encode_spz(g);
    ASSERT_GT(bytes.size(), 2u);
    EXPECT_EQ(bytes[0], 0x1f);  // gzip
    EXPECT_EQ(bytes[1], 0x8b);
    expect_within_quantisation(g, decode_spz(bytes));
  }
}

TEST(Spz, HeaderAndSizesFollowTheFormat) {
  const GaussianHost g = random_gaussians(10, 1, 5);
  const std::vector<uint8_t> gz = encode_spz(g);
  std::vector<uint8_t> raw(4096);
  z_stream s{};
  ASSERT_EQ(inflateInit2(&s, 16 + MAX_WBITS), Z_OK);
  s.next_in = const_cast<Bytef*>(gz.data());
  s.avail_in = uInt(gz.size());
  s.next_out = raw.data();
  s.avail_out = uInt(raw.size());
  ASSERT_EQ(inflate(&s, Z_FINISH), Z_STREAM_END);
  raw.resize(raw.size() - s.avail_out);
  inflateEnd(&s);
  // 16-byte header + per Gaussian 9 (position) + 1 (alpha) + 3 (colour) + 3 (scale) + 4 (rotation) + 9 (SH 1)
  EXPECT_EQ(raw.size(), 16u + 10u * 29u);
  const uint8_t header[16] = {0x4e, 0x47, 0x53, 0x50, 3, 0, 0, 0, 10, 0, 0, 0, 1, 12, 0, 0};
  EXPECT_TRUE(std::equal(header, header + 16, raw.begin()));
}

TEST(Spz, RdfToRubConversionRoundTrips) {
  const GaussianHost g = random_gaussians(50, 3, 30);
  const SpzOptions opt{true};
  expect_within_quantisation(g, decode_spz(encode_spz(g, opt), opt));
  // without the inverse conversion, y and z come back mirrored
  const GaussianHost raw = decode_spz(encode_spz(g, opt));
  EXPECT_NEAR(raw.means[0].y(), -g.means[0].y(), 1e-3f);
  EXPECT_NEAR(raw.means[0].x(), g.means[0].x(), 1e-3f);
}

TEST(Spz, RejectsCorruptInput) {
  EXPECT_THROW(decode_spz({1, 2, 3}), std::runtime_error);
  std::vector<uint8_t> bytes = encode_spz(random_gaussians(4, 0, 1));
  bytes.resize(bytes.size() / 2);
  EXPECT_THROW(decode_spz(bytes), std::runtime_error);
}

}  // namespace
}  // namespace rrg
