// Volume files: round trip on every device, and rejection of damaged files naming the file.
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_io.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"
#include "tests/support/test_support.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

namespace rrg {
namespace {

const Intrinsics kK{150.0f, 150.0f, 79.5f, 59.5f, 160, 120};

TsdfVolume fused(const Device& device) {
  TsdfParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  p.reflection_window = 3;
  p.band_sigmas = 2.5f;  // not the defaults: the file must carry them
  p.noise.a = 0.002f;
  TsdfVolume v(p, device);
  const test::Scene scene = test::sphere_scene({0, 0, 0}, 0.25f);
  const auto poses = test::cameras_around({0, 0, 0}, 0.9f);
  test::fuse_scene(v, scene, kK, poses, Color(0.3f, 0.2f, 0.1f));
  // one identification frame, so the reflection attributes are non-trivial
  Image<int32_t> ids(kK.width, kK.height, 4);
  Image<uint8_t> mask(kK.width, kK.height, 1);
  const auto ids_d = DeviceImage<int32_t>::from_host(ids, device);
  const auto mask_d = DeviceImage<uint8_t>::from_host(mask, device);
  const ReflectionObservation refl{&ids_d, &mask_d, {}};
  const auto d = DeviceImage<float>::from_host(scene.render_depth(kK, poses[2]), device);
  const auto c = DeviceImage<Color>::from_host(ColorImage(kK.width, kK.height, Color(0.9f, 0.1f, 0.5f)), device);
  integrate(v, d, c, kK, poses[2], &refl);
  return v;
}

std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void write_bytes(const std::filesystem::path& p, const std::vector<uint8_t>& b) {
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

template <class T>
std::vector<uint8_t> image_bytes(const DeviceImage<T>& image) {
  const Image<T> host = image.to_host();
  const auto* p = reinterpret_cast<const uint8_t*>(host.data());
  return {p, p + host.size() * sizeof(T)};
}

TEST(TsdfIo, SaveLoadRoundTripIsIdenticalOnEveryDevice) {
  const test::TempDir tmp("tsdf-io");
  const auto novel = test::look_at({0.5f, 0.3f, -0.6f}, {0, 0, 0});
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const TsdfVolume a = fused(device);
    save_volume(a, tmp / "v.tsdf");
    for (const Device& target : available_devices()) {
      const TsdfVolume b = load_volume(tmp / "v.tsdf", target);
      EXPECT_EQ(b.version(), a.version());
      EXPECT_EQ(b.num_blocks(), a.num_blocks());
      EXPECT_EQ(b.params().reflection_window, 3);
      EXPECT_EQ(b.params().band_sigmas, 2.5f);
      EXPECT_EQ(b.params().noise.a, 0.002f);
      EXPECT_EQ(b.params().noise.b, DepthNoiseModel{}.b);
      EXPECT_EQ(b.params().noise.z0, DepthNoiseModel{}.z0);
      EXPECT_EQ(test::flatten_voxels(b), test::flatten_voxels(a));
      if (target == device) {
        const RaycastResult ra = raycast(a, kK, novel), rb = raycast(b, kK, novel);
        EXPECT_EQ(image_bytes(ra.depth), image_bytes(rb.depth));
        EXPECT_EQ(image_bytes(ra.colors), image_bytes(rb.colors));
        EXPECT_EQ(image_bytes(ra.plane_ids), image_bytes(rb.plane_ids));
        EXPECT_EQ(image_bytes(ra.color_variance), image_bytes(rb.color_variance));
        EXPECT_EQ(image_bytes(ra.reflection), image_bytes(rb.reflection));
        // The loaded pool holds the blocks in file (coordinate) order, not allocation order: the
        // mesh must still come out in the same vertex and triangle order (the same Draco bytes).
        const TriangleMesh ma = extract_mesh(a), mb = extract_mesh(b);
        ASSERT_GT(ma.triangles.size(), 0u);
        EXPECT_TRUE(ma.vertices == mb.vertices) << "vertex order depends on block allocation order";
        EXPECT_TRUE(ma.triangles == mb.triangles);
        EXPECT_TRUE(ma.colors == mb.colors);
      }
    }
  }
}

// A file loaded with a residency rule: the blocks it rejects go straight to host memory, as
// stream_out would have put them; nothing is lost and the pool holds the resident blocks alone.
TEST(TsdfIo, LoadingWithAResidencyRuleStreamsTheOtherBlocksOut) {
  const test::TempDir tmp("tsdf-io-resident");
  const auto novel = test::look_at({0.5f, 0.3f, -0.6f}, {0, 0, 0});
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const TsdfVolume a = fused(device);
    save_volume(a, tmp / "v.tsdf");
    const auto upper = [](const Eigen::Vector3i& b) { return b.y() >= 0; };  // about half the sphere
    TsdfVolume b = load_volume(tmp / "v.tsdf", device, upper);
    const TsdfVolume whole = load_volume(tmp / "v.tsdf", device);
    int64_t kept = 0;
    for (const BlockData& blk : a.read_all_blocks()) kept += upper(blk.coord);
    ASSERT_GT(kept, 0);
    ASSERT_LT(kept, a.num_blocks());
    EXPECT_EQ(b.num_blocks(), kept);
    EXPECT_EQ(b.num_host_blocks(), a.num_blocks() - kept);
    for (const Eigen::Vector3i& c : b.block_coords()) EXPECT_TRUE(upper(c));
    for (const Eigen::Vector3i& c : b.host_block_coords()) EXPECT_FALSE(upper(c));
    EXPECT_EQ(b.version(), a.version());
    EXPECT_EQ(test::flatten_voxels(b), test::flatten_voxels(a));  // every block, wherever it is held
    EXPECT_LT(b.memory().device_bytes, whole.memory().device_bytes) << "the pool was sized for every block";
    EXPECT_GT(b.memory().host_bytes, 0u);
    // A block the volume holds already, resident or not, is refused.
    EXPECT_THROW(b.insert_host_blocks({*a.read_block(b.block_coords().front())}), std::invalid_argument);
    EXPECT_THROW(b.insert_host_blocks({*a.read_block(b.host_block_coords().front())}), std::invalid_argument);
    // Brought back, they are the volume the file holds.
    EXPECT_EQ(b.stream_in_all(), a.num_blocks() - kept);
    const RaycastResult ra = raycast(a, kK, novel), rb = raycast(b, kK, novel);
    EXPECT_EQ(image_bytes(ra.depth), image_bytes(rb.depth));
    EXPECT_EQ(image_bytes(ra.color_variance), image_bytes(rb.color_variance));
  }
}

void expect_load_error(const std::filesystem::path& p, const std::string& what) {
  try {
    load_volume(p, Device::cpu());
    FAIL() << "loaded a bad file, expected: " << what;
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST(TsdfIo, DamagedFilesAreRejectedNamingTheFile) {
  const test::TempDir tmp("tsdf-io");
  save_volume(fused(Device::cpu()), tmp / "good.tsdf");
  const std::vector<uint8_t> good = read_bytes(tmp / "good.tsdf");
  ASSERT_GT(good.size(), 1000u);

  auto flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  write_bytes(tmp / "flipped.tsdf", flipped);
  expect_load_error(tmp / "flipped.tsdf", "checksum mismatch");

  write_bytes(tmp / "short.tsdf", std::vector<uint8_t>(good.begin(), good.end() - 100));
  expect_load_error(tmp / "short.tsdf", "truncated");
  write_bytes(tmp / "header.tsdf", std::vector<uint8_t>(good.begin(), good.begin() + 20));
  expect_load_error(tmp / "header.tsdf", "truncated header");

  auto magic = good;
  magic[0] = 'X';
  write_bytes(tmp / "magic.tsdf", magic);
  expect_load_error(tmp / "magic.tsdf", "bad magic");

  auto version = good;
  version[8] = 7;
  write_bytes(tmp / "version.tsdf", version);
  expect_load_error(tmp / "version.tsdf", "unsupported format version 7");

  expect_load_error(tmp / "missing.tsdf", "cannot open");
}

// A version 1 file (before the truncation band) is the version 2 file without the band's 16 bytes
// after the reflection window (offset 40): it loads with the same voxels and the constant band it
// was fused with, so fusion goes on as before.
TEST(TsdfIo, VersionOneFilesLoadWithTheConstantBand) {
  const test::TempDir tmp("tsdf-io");
  const TsdfVolume a = fused(Device::cpu());
  save_volume(a, tmp / "v2.tsdf");
  const std::vector<uint8_t> v2 = read_bytes(tmp / "v2.tsdf");
  ASSERT_EQ(v2[8], kTsdfFormatVersion);
  std::vector<uint8_t> v1(v2.begin(), v2.begin() + 40);
  v1.insert(v1.end(), v2.begin() + 56, v2.end());
  v1[8] = 1;
  write_bytes(tmp / "v1.tsdf", v1);
  const TsdfVolume b = load_volume(tmp / "v1.tsdf", Device::cpu());
  EXPECT_EQ(b.params().band_sigmas, 0.0f);
  EXPECT_EQ(b.params().reflection_window, 3);
  EXPECT_EQ(b.version(), a.version());
  EXPECT_EQ(test::flatten_voxels(b), test::flatten_voxels(a));
  // a version 2 file cut after a version 1 header's length (72 bytes) but inside its own (88)
  write_bytes(tmp / "v2-short.tsdf", std::vector<uint8_t>(v2.begin(), v2.begin() + 80));
  expect_load_error(tmp / "v2-short.tsdf", "truncated header");
}

TEST(TsdfIo, FailedSaveLeavesNothingBehind) {
  const test::TempDir tmp("tsdf-io");
  write_bytes(tmp / "not_a_dir", {1, 2, 3});
  EXPECT_ANY_THROW(save_volume(fused(Device::cpu()), tmp / "not_a_dir" / "v.tsdf"));
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(tmp.path())) ++entries;
  EXPECT_EQ(entries, 1u);
}

TEST(TsdfIo, Fnv1aKnownAnswers) {
  const std::string a = "a", foobar = "foobar";
  EXPECT_EQ(fnv1a64({}), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64({reinterpret_cast<const uint8_t*>(a.data()), a.size()}), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64({reinterpret_cast<const uint8_t*>(foobar.data()), foobar.size()}), 0x85944171f73967e8ull);
}

}  // namespace
}  // namespace rrg
