#pragma once
// The mesh of a session cut into fixed spatial chunks for the browser viewer (docs/viewer.md):
// a chunk is a cube of kChunkBlocks³ TSDF blocks (8 voxels each), keyed "x_y_z" by its chunk
// coordinate. Each chunk carries the volume version of the last fusion that can change its mesh
// (its own blocks, or a block on its +x / +y / +z faces, whose voxels close its boundary cubes),
// so a client that already holds a chunk's version (ETag) is not sent it again. Chunk meshes are
// Draco-encoded on demand and cached per version.
#include "core/slam/session.h"

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace rrg::server {

inline constexpr int kChunkBlocks = 8;

struct MeshChunkInfo {
  std::string key;                 // "x_y_z"
  uint64_t version = 0;            // volume version of its last change
  std::string etag;                // quoted, e.g. "\"c12-3_0_1\""
  std::optional<size_t> bytes;     // Draco size when already encoded
};

// A chunk's Draco bytes; empty when the chunk's blocks hold no triangles yet.
struct MeshChunkData {
  std::string etag;
  std::shared_ptr<const std::vector<uint8_t>> drc;
};

// One per session; thread-safe.
class MeshChunks {
 public:
  // Brings the chunk table up to date with the session (blocks fused since the last call) and
  // lists the chunks that own at least one block, sorted by key.
  std::vector<MeshChunkInfo> list(const Session& session);
  // The chunk's Draco (encoded now, or from the cache). Throws std::invalid_argument("key: ...") for
  // a malformed key, std::out_of_range for a chunk without blocks.
  MeshChunkData get(const Session& session, const std::string& key);

  static std::optional<Eigen::Vector3i> parse_key(const std::string& key);
  static std::string key_of(const Eigen::Vector3i& chunk);

 private:
  struct Chunk {
    std::vector<Eigen::Vector3i> blocks;
    uint64_t version = 0;
    uint64_t cached_version = 0;
    std::shared_ptr<const std::vector<uint8_t>> cached;  // valid when cached_version == version
  };
  void update(const Session& session);  // caller holds mutex_

  std::mutex mutex_;
  uint64_t seen_version_ = 0;
  bool seen_any_ = false;
  std::map<std::string, Chunk> chunks_;
};

}  // namespace rrg::server
