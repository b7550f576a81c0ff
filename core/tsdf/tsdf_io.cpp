#include "core/tsdf/tsdf_io.h"

#include "core/io/atomic_file.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace rrg {
namespace {

static_assert(std::endian::native == std::endian::little, "the TSDF file format is little-endian");

// magic 8, version 4, voxel bytes 4, 4 floats, 2 int32, [version 2: the band's 4 floats,] volume
// version 8, blocks 8, payload bytes 8, checksum 8
constexpr size_t kHeaderBytesV1 = 8 + 4 + 4 + 16 + 8 + 8 + 8 + 8 + 8;
constexpr size_t kHeaderBytes = kHeaderBytesV1 + 16;
constexpr size_t kBlockBytes = 3 * 4 + 8 + kBlockVoxels * sizeof(Voxel);

template <class T>
void put(std::vector<uint8_t>& out, const T& value) {
  const auto* p = reinterpret_cast<const uint8_t*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

struct Reader {
  const std::vector<uint8_t>& bytes;
  size_t pos = 0;
  template <class T>
  T get() {
    T value;
    std::memcpy(&value, bytes.data() + pos, sizeof(T));
    pos += sizeof(T);
    return value;
  }
};

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error("load_volume: " + path.string() + ": " + what);
}

}  // namespace

uint64_t fnv1a64(std::span<const uint8_t> bytes, uint64_t seed) {
  uint64_t h = seed;
  for (uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  return h;
}

void save_volume(const TsdfVolume& volume, const std::filesystem::path& path) {
  const std::vector<BlockData> blocks = volume.read_all_blocks();
  std::vector<uint8_t> payload;
  payload.reserve(blocks.size() * kBlockBytes);
  for (const BlockData& b : blocks) {
    put(payload, int32_t(b.coord.x()));
    put(payload, int32_t(b.coord.y()));
    put(payload, int32_t(b.coord.z()));
    put(payload, b.version);
    const auto* p = reinterpret_cast<const uint8_t*>(b.voxels.data());
    payload.insert(payload.end(), p, p + b.voxels.size() * sizeof(Voxel));
  }
  const TsdfParams& prm = volume.params();
  std::vector<uint8_t> header;
  header.insert(header.end(), std::begin(kTsdfMagic), std::end(kTsdfMagic));
  put(header, kTsdfFormatVersion);
  put(header, uint32_t(sizeof(Voxel)));
  put(header, prm.voxel_size);
  put(header, prm.truncation);
  put(header, prm.min_depth);
  put(header, prm.max_depth);
  put(header, int32_t(prm.max_weight));
  put(header, int32_t(prm.reflection_window));
  put(header, prm.band_sigmas);
  put(header, prm.noise.a);
  put(header, prm.noise.b);
  put(header, prm.noise.z0);
  put(header, volume.version());
  put(header, uint64_t(blocks.size()));
  put(header, uint64_t(payload.size()));
  put(header, fnv1a64(payload));
  io::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp, std::ios::binary);
    f.write(reinterpret_cast<const char*>(header.data()), std::streamsize(header.size()));
    f.write(reinterpret_cast<const char*>(payload.data()), std::streamsize(payload.size()));
    f.close();
    if (!f) throw std::runtime_error("save_volume: cannot write " + path.string());
  });
}

TsdfVolume load_volume(const std::filesystem::path& path, const Device& device,
                       const std::function<bool(const Eigen::Vector3i&)>& resident) {
  std::ifstream f(path, std::ios::binary);
  if (!f) fail(path, "cannot open file");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (bytes.size() < sizeof(kTsdfMagic) || std::memcmp(bytes.data(), kTsdfMagic, sizeof(kTsdfMagic)) != 0)
    fail(path, "not an RRG TSDF volume (bad magic)");
  if (bytes.size() < kHeaderBytesV1) fail(path, "truncated header (" + std::to_string(bytes.size()) + " bytes)");
  Reader r{bytes, sizeof(kTsdfMagic)};
  const auto version = r.get<uint32_t>();
  if (version != 1 && version != kTsdfFormatVersion)
    fail(path, "unsupported format version " + std::to_string(version) + " (this build reads 1 to " +
                   std::to_string(kTsdfFormatVersion) + ")");
  const size_t header_bytes = version == 1 ? kHeaderBytesV1 : kHeaderBytes;
  if (bytes.size() < header_bytes) fail(path, "truncated header (" + std::to_string(bytes.size()) + " bytes)");
  const auto voxel_bytes = r.get<uint32_t>();
  if (voxel_bytes != sizeof(Voxel)) fail(path, "voxel layout of " + std::to_string(voxel_bytes) + " bytes, expected 24");
  TsdfParams prm;
  prm.voxel_size = r.get<float>();
  prm.truncation = r.get<float>();
  prm.min_depth = r.get<float>();
  prm.max_depth = r.get<float>();
  prm.max_weight = r.get<int32_t>();
  prm.reflection_window = r.get<int32_t>();
  if (version == 1) {
    prm.band_sigmas = 0.0f;  // fused with the constant band: fusion goes on as it was
  } else {
    prm.band_sigmas = r.get<float>();
    prm.noise.a = r.get<float>();
    prm.noise.b = r.get<float>();
    prm.noise.z0 = r.get<float>();
  }
  const auto volume_version = r.get<uint64_t>();
  const auto n_blocks = r.get<uint64_t>();
  const auto payload_bytes = r.get<uint64_t>();
  const auto checksum = r.get<uint64_t>();
  if (payload_bytes != n_blocks * kBlockBytes) fail(path, "inconsistent header (payload size vs block count)");
  if (bytes.size() - header_bytes != payload_bytes)
    fail(path, "truncated or oversized: payload of " + std::to_string(bytes.size() - header_bytes) +
                   " bytes, header says " + std::to_string(payload_bytes));
  if (fnv1a64(std::span(bytes).subspan(header_bytes)) != checksum) fail(path, "checksum mismatch (corrupted file)");
  try {
    prm.validate();
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
  std::vector<BlockData> blocks, streamed_out;  // resident / loaded into host memory
  blocks.reserve(resident ? 0 : n_blocks);
  for (uint64_t i = 0; i < n_blocks; ++i) {
    BlockData b;
    b.coord.x() = r.get<int32_t>();
    b.coord.y() = r.get<int32_t>();
    b.coord.z() = r.get<int32_t>();
    b.version = r.get<uint64_t>();
    b.voxels.resize(kBlockVoxels);
    std::memcpy(b.voxels.data(), bytes.data() + r.pos, kBlockVoxels * sizeof(Voxel));
    r.pos += kBlockVoxels * sizeof(Voxel);
    (!resident || resident(b.coord) ? blocks : streamed_out).push_back(std::move(b));
  }
  prm.initial_blocks = std::max<int64_t>(int64_t(blocks.size()), 1);
  TsdfVolume volume(prm, device);
  try {
    volume.insert_blocks(blocks);
    volume.insert_host_blocks(std::move(streamed_out));
  } catch (const std::invalid_argument& e) {
    fail(path, e.what());
  }
  volume.set_version(volume_version);
  return volume;
}

}  // namespace rrg
