#pragma once
// The augmented TSDF volume S (paper §3.1, §4.1.4): a sparse voxel-hashed grid of 8³-voxel blocks
// on one device (CPU or CUDA), no dense grid. Blocks are allocated from each frame's depth inside
// the truncation band; the hash and the block pool grow on the host between frames (rehash), and
// an insert that finds no slot makes the pass run again on a bigger table, so no block is dropped.
// Blocks far from the camera can be streamed out to host memory and come back when touched again.
//
// The algorithms on the volume live in their own headers:
//   tsdf_integrate.h  fusion of a posed RGB-D frame (+ reflection attributes on identification frames)
//   tsdf_raycast.h    D_t, vertices, normals, C_t, plane ids I, R_raw / R, C_var for any camera
//   tsdf_mesh.h       marching cubes (whole volume, or a set of blocks) with colours and plane ids
//   tsdf_io.h         versioned, checksummed save / load
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/common/depth_maps.h"
#include "core/tsdf/fusion_pixel.h"
#include "core/tsdf/tsdf_params.h"
#include "core/tsdf/voxel.h"
#include "core/tsdf/tsdf_storage_impl.h"
#include "core/tsdf/voxel_hash_device.h"

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

namespace rrg {

struct MemoryUsage {
  size_t device_bytes = 0;  // hash, block pool, per-block data and the per-frame scratch on the volume's device
  size_t host_bytes = 0;    // streamed-out blocks held in host memory
};

// A block's voxels as stored (for inspection, tests, streaming and files).
struct BlockData {
  Eigen::Vector3i coord;          // block coordinate (voxel g lies in block floor(g / 8))
  uint64_t version = 0;           // volume version of the last frame that fused into it
  std::vector<Voxel> voxels;      // 512, x fastest
};

class TsdfVolume {
 public:
  // Throws std::invalid_argument for bad params, std::runtime_error when the device is unusable.
  TsdfVolume(const TsdfParams& params, const Device& device);
  TsdfVolume(TsdfVolume&&) noexcept = default;
  TsdfVolume& operator=(TsdfVolume&&) noexcept = default;

  const TsdfParams& params() const { return params_; }
  const Device& device() const { return device_; }
  int64_t num_blocks() const { return num_blocks_; }                     // resident on the device
  int64_t num_host_blocks() const { return int64_t(host_blocks_.size()); }  // streamed out
  int64_t hash_capacity() const { return int64_t(hash_keys_.size()); }
  int64_t pool_capacity() const { return int64_t(block_keys_.size()); }  // blocks the pool holds room for
  uint64_t version() const { return version_; }  // number of integrated frames (and loads)
  MemoryUsage memory() const;

  // Resident block coordinates in pool order.
  std::vector<Eigen::Vector3i> block_coords() const;
  // Blocks fused into after version `since` (0 = every block ever fused), resident first (pool
  // order), then streamed out (sorted): for streaming changed mesh blocks, which meshing sees only
  // once they are resident again.
  std::vector<Eigen::Vector3i> changed_blocks(uint64_t since) const;
  // One block, resident or streamed out; nullopt when never allocated.
  std::optional<BlockData> read_block(const Eigen::Vector3i& coord) const;
  // Every block (resident and streamed out), sorted by coordinate (x, then y, then z).
  std::vector<BlockData> read_all_blocks() const;

  // Streaming: moves resident blocks whose centre is farther than radius from centre to host
  // memory, or brings streamed-out blocks within radius back. Returns the number of blocks moved.
  // Integration brings back any streamed-out block that a frame touches.
  int64_t stream_out(const Eigen::Vector3f& center, float radius);
  int64_t stream_in(const Eigen::Vector3f& center, float radius);
  int64_t stream_in_all();
  // Gives back the pool's room beyond max(blocks, num_blocks()) blocks: after a read brought many
  // streamed-out blocks back and sent them out again, the pool returns to its size before.
  void shrink_pool(int64_t blocks);
  // The same for listed blocks: coordinates not resident (for stream_out) or not streamed out
  // (for stream_in) are ignored.
  int64_t stream_out(std::span<const Eigen::Vector3i> blocks);
  int64_t stream_in(std::span<const Eigen::Vector3i> blocks);
  // Coordinates of the streamed-out blocks, sorted (x, then y, then z).
  std::vector<Eigen::Vector3i> host_block_coords() const;
  // The streamed-out blocks for which keep(coord) holds, sorted (x, then y, then z).
  std::vector<Eigen::Vector3i> host_blocks_where(const std::function<bool(const Eigen::Vector3i&)>& keep) const;

  // --- used by the algorithms (tsdf_integrate.cpp, tsdf_raycast.cpp, ...) -----------------------
  kernel::HashView hash_view() { return {hash_keys_.span(), hash_values_.span()}; }
  kernel::HashView hash_view() const;
  // The two voxel layers of the resident blocks (voxel.h), [num_blocks * 512] each.
  Span<TsdfVoxel> geometry() { return {geometry_.data(), num_blocks_ * kBlockVoxels}; }
  Span<const TsdfVoxel> geometry() const { return {geometry_.data(), num_blocks_ * kBlockVoxels}; }
  Span<AttrVoxel> attributes() { return {attributes_.data(), num_blocks_ * kBlockVoxels}; }
  Span<const AttrVoxel> attributes() const { return {attributes_.data(), num_blocks_ * kBlockVoxels}; }
  Span<const uint64_t> block_keys() const { return {block_keys_.data(), num_blocks_}; }
  Span<uint64_t> block_versions() { return {block_versions_.data(), num_blocks_}; }
  // Crossing box code of each resident block (crossing_box_device.h; the raycast's range image).
  // Kept current by the volume where it writes voxels (streaming, insert_blocks) and by
  // integrate(), which calls update_crossing_boxes on its active blocks after fusing them; code
  // that writes voxels through geometry() itself must call it too.
  Span<const uint32_t> crossing_boxes() const { return {crossing_boxes_.data(), num_blocks_}; }
  void update_crossing_boxes(Span<const int32_t> blocks);
  // Allocates (and brings back from the host) every block on the rays of the valid depth pixels
  // within [d - ε, d + ε]; returns the indices of the blocks touched by this frame (the active set),
  // valid until the next call. Increments version().
  Span<const int32_t> allocate_from_depth(const DeviceImage<float>& depth, const Intrinsics& K,
                                          const Eigen::Matrix3f& R_wc, const Eigen::Vector3f& t_wc);
  // Adds blocks that are not in the volume (files, streaming). Throws if one is already present.
  void insert_blocks(std::span<const BlockData> blocks);
  // The same, straight into host memory, as stream_out leaves blocks (a file loaded by a session
  // that streams: its far blocks never take pool slots).
  void insert_host_blocks(std::vector<BlockData> blocks);
  void set_version(uint64_t v) { version_ = v; }
  // Per-frame images of integrate(), kept between frames so that fusing a frame allocates nothing
  // once the first frame of a size has been fused: V_k^l, N_k^l and the per-pixel fusion data.
  struct FrameScratch {
    VertexNormalMaps maps;
    DeviceImage<kernel::FusionPixel> pixels;
  };
  FrameScratch& frame_scratch() { return frame_scratch_; }

 private:
  void ensure_pool(int64_t blocks);       // pool capacity >= blocks (copying)
  void resize_pool(int64_t capacity);     // capacity >= num_blocks_, copying the resident blocks
  void rehash(int64_t capacity);          // new table of `capacity` slots with every resident block
  void grow_hash_for(int64_t blocks);     // keeps the load factor <= 1/2
  void append_blocks(std::span<const uint64_t> keys, std::span<const int64_t> slots,
                     std::span<const BlockData* const> restored, int64_t active_offset);
  kernel::PoolView pool();
  // Voxel records (on the volume's device) of the resident blocks `index` into the first
  // index.size() blocks of `records`, and the way back.
  void gather_records(std::span<const int32_t> index, Buffer<Voxel>& records) const;
  void scatter_records(const Buffer<Voxel>& records, std::span<const int32_t> index);
  // Records move between the pool and host memory through staging of at most kTransferBlocks
  // blocks (12 MB), so streaming, saving or loading much of a map needs little memory beyond the
  // pool: sink(j, voxels) receives slot slots[j]'s records, source(j) gives them.
  static constexpr size_t kTransferBlocks = 1024;
  template <class Sink>
  void download_blocks(std::span<const int32_t> slots, Sink&& sink) const;
  template <class Source>
  void upload_blocks(std::span<const int32_t> slots, Source&& source);
  void move_blocks(std::span<const int32_t> from, std::span<const int32_t> to);  // slot from[j] -> to[j]
  void insert_block_ptrs(std::span<const BlockData* const> blocks);  // insert_blocks
  // Their keys, after checking each is in range, of 512 voxels and not resident (else
  // std::invalid_argument naming `who`).
  std::vector<uint64_t> keys_of_new_blocks(std::span<const BlockData* const> blocks, const char* who) const;
  // Moves the resident blocks whose key satisfies leave(key) to host memory.
  template <class Leave>
  int64_t stream_out_where(Leave leave);
  int64_t stream_in_blocks(std::vector<const BlockData*> back);  // inserts them, then drops their host copies

  TsdfParams params_;
  Device device_;
  Buffer<uint64_t> hash_keys_;       // [capacity] packed block coordinates, kEmptyKey = free
  Buffer<int32_t> hash_values_;      // [capacity] block index, -1 = free
  Buffer<TsdfVoxel> geometry_;       // [pool capacity * 512] geometry layer; free slots (blocks >= num_blocks_) zero
  Buffer<AttrVoxel> attributes_;     // [pool capacity * 512] attribute layer; free slots zero
  Buffer<uint64_t> block_keys_;      // [pool capacity]
  Buffer<uint64_t> block_versions_;  // [pool capacity] version of the last fusion into the block
  Buffer<int32_t> block_stamps_;     // [pool capacity] allocation pass that last listed it active
  Buffer<uint32_t> crossing_boxes_;  // [pool capacity] crossing box codes; free slots kBoxUnknown (0)
  int64_t num_blocks_ = 0;
  uint64_t version_ = 0;
  int32_t pass_id_ = 0;
  // Scratch of allocate_from_depth, kept between frames.
  Buffer<uint64_t> new_keys_;
  Buffer<int32_t> new_slots_;
  Buffer<int32_t> active_;
  Buffer<int32_t> counters_;
  FrameScratch frame_scratch_;
  std::unordered_map<uint64_t, BlockData> host_blocks_;  // streamed out, by key
};

}  // namespace rrg
