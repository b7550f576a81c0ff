#include "server/mesh_chunks.h"

#include "core/io/draco_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <stdexcept>
#include <tuple>

namespace rrg::server {

namespace {

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

Eigen::Vector3i chunk_of(const Eigen::Vector3i& block) {
  return {floor_div(block.x(), kChunkBlocks), floor_div(block.y(), kChunkBlocks), floor_div(block.z(), kChunkBlocks)};
}

std::string etag_of(const std::string& key, uint64_t version) { return fmt::format("\"c{}-{}\"", version, key); }

}  // namespace

std::string MeshChunks::key_of(const Eigen::Vector3i& c) { return fmt::format("{}_{}_{}", c.x(), c.y(), c.z()); }

std::optional<Eigen::Vector3i> MeshChunks::parse_key(const std::string& key) {
  Eigen::Vector3i c;
  const char* p = key.data();
  const char* end = key.data() + key.size();
  for (int i = 0; i < 3; ++i) {
    if (i > 0) {
      if (p == end || *p != '_') return std::nullopt;
      ++p;
    }
    const auto r = std::from_chars(p, end, c[i]);
    if (r.ec != std::errc() || r.ptr == p) return std::nullopt;
    p = r.ptr;
  }
  if (p != end || key.size() > 40) return std::nullopt;
  return c;
}

void MeshChunks::update(const Session& session) {
  const Session::ChangedBlocks changed = session.changed_blocks(seen_any_ ? seen_version_ : 0);
  for (const Eigen::Vector3i& b : changed.blocks) {
    Chunk& own = chunks_[key_of(chunk_of(b))];
    if (std::find(own.blocks.begin(), own.blocks.end(), b) == own.blocks.end()) own.blocks.push_back(b);
    // The cubes of the blocks at b - (dx, dy, dz) read b's voxels: their chunks change too.
    for (int d = 0; d < 8; ++d) {
      const Eigen::Vector3i n = b - Eigen::Vector3i(d & 1, (d >> 1) & 1, (d >> 2) & 1);
      auto it = chunks_.find(key_of(chunk_of(n)));
      if (it != chunks_.end()) it->second.version = std::max(it->second.version, changed.volume_version);
    }
  }
  seen_version_ = changed.volume_version;
  seen_any_ = true;
}

std::vector<MeshChunkInfo> MeshChunks::list(const Session& session) {
  std::lock_guard lock(mutex_);
  update(session);
  std::vector<MeshChunkInfo> out;
  for (const auto& [key, c] : chunks_) {
    if (c.blocks.empty()) continue;
    MeshChunkInfo info{key, c.version, etag_of(key, c.version), std::nullopt};
    if (c.cached && c.cached_version == c.version) info.bytes = c.cached->size();
    out.push_back(std::move(info));
  }
  return out;
}

MeshChunkData MeshChunks::get(const Session& session, const std::string& key) {
  if (!parse_key(key)) throw std::invalid_argument("key: '" + key + "' is not a chunk key x_y_z (integers)");
  std::vector<Eigen::Vector3i> blocks;
  uint64_t version = 0;
  {
    std::lock_guard lock(mutex_);
    update(session);
    const auto it = chunks_.find(key);
    if (it == chunks_.end() || it->second.blocks.empty()) throw std::out_of_range("chunk " + key + " has no TSDF blocks");
    const Chunk& c = it->second;
    if (c.cached && c.cached_version == c.version) return {etag_of(key, c.version), c.cached};
    blocks = c.blocks;
    version = c.version;
  }
  // A fixed block order: the same blocks give the same mesh and the same bytes.
  std::sort(blocks.begin(), blocks.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  });
  // Encoded outside the lock (other chunks are served meanwhile). A fusion after `version` only
  // makes this chunk's next version newer, so the bytes are at least as new as their ETag says.
  const TriangleMesh mesh = session.mesh_of_blocks(blocks);
  auto drc = std::make_shared<std::vector<uint8_t>>();
  if (!mesh.triangles.empty()) *drc = io::encode_draco(mesh);
  std::lock_guard lock(mutex_);
  Chunk& c = chunks_[key];
  if (c.version == version) {
    c.cached = drc;
    c.cached_version = version;
  }
  return {etag_of(key, version), std::move(drc)};
}

}  // namespace rrg::server
