#include "core/tsdf/tsdf_volume.h"

#include "core/common/dispatch.h"
#include "core/tsdf/tsdf_storage_impl.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace rrg {
namespace {

int64_t next_pow2(int64_t n) {
  int64_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

template <class T>
void resize_keep(Buffer<T>& b, int64_t capacity, int64_t keep, const Device& device) {
  Buffer<T> bigger(size_t(capacity), device);
  if (keep > 0) mem::copy(bigger.data(), device, b.data(), device, size_t(keep) * sizeof(T));
  b = std::move(bigger);
}

// Zeroes elements [from, to) of b: free pool slots hold zero voxels (TsdfVolume's pool invariant).
template <class T>
void zero_range(Buffer<T>& b, int64_t from, int64_t to, const Device& device) {
  if (to > from) mem::fill_zero(b.data() + from, size_t(to - from) * sizeof(T), device);
}

// Initial hash slots: 4 per initial pool block, and at least 65536 (768 KB), enough for the ~20k
// blocks a 640x480 frame at 5 mm touches without a grow-and-retry pass. Not more: every ray step
// through empty space probes the table for an absent block, so a table far beyond the load needed
// misses the caches for nothing (grow_hash_for keeps the load at most 1/2 as blocks come).
constexpr int64_t kHashSlotsPerBlock = 4;
constexpr int64_t kMinHashSlots = 65536;

}  // namespace

TsdfVolume::TsdfVolume(const TsdfParams& params, const Device& device) : params_(params), device_(device) {
  params_.validate();
  require_device(device_);
  const int64_t blocks = params_.initial_blocks;
  // Free pool slots are zero voxels (weight 0, no colour, no statistics), so a new block needs no
  // initialisation: the pool is zeroed here (its pages committed once, as Open3D's VoxelBlockGrid
  // does for its capacity), on growth and where compaction frees slots.
  geometry_ = Buffer<TsdfVoxel>::zeros(size_t(blocks) * kBlockVoxels, device_);
  attributes_ = Buffer<AttrVoxel>::zeros(size_t(blocks) * kBlockVoxels, device_);
  block_keys_ = Buffer<uint64_t>(size_t(blocks), device_);
  block_versions_ = Buffer<uint64_t>(size_t(blocks), device_);
  block_stamps_ = Buffer<int32_t>::zeros(size_t(blocks), device_);
  crossing_boxes_ = Buffer<uint32_t>::zeros(size_t(blocks), device_);
  active_ = Buffer<int32_t>(size_t(blocks), device_);
  counters_ = Buffer<int32_t>::zeros(4, device_);
  rehash(next_pow2(std::max(kHashSlotsPerBlock * blocks, kMinHashSlots)));
}

kernel::HashView TsdfVolume::hash_view() const {
  // Read-only kernels take the same view; they never write through it.
  auto& self = const_cast<TsdfVolume&>(*this);
  return {self.hash_keys_.span(), self.hash_values_.span()};
}

MemoryUsage TsdfVolume::memory() const {
  MemoryUsage m;
  m.device_bytes = hash_keys_.size() * sizeof(uint64_t) + hash_values_.size() * sizeof(int32_t) +
                   geometry_.size() * sizeof(TsdfVoxel) + attributes_.size() * sizeof(AttrVoxel) +
                   block_keys_.size() * (2 * sizeof(uint64_t) + sizeof(int32_t) + sizeof(uint32_t)) +
                   new_keys_.size() * sizeof(uint64_t) + new_slots_.size() * sizeof(int32_t) +
                   active_.size() * sizeof(int32_t) + counters_.size() * sizeof(int32_t) +
                   (frame_scratch_.maps.vertices.buffer().size() + frame_scratch_.maps.normals.buffer().size()) *
                       sizeof(Eigen::Vector3f) +
                   frame_scratch_.pixels.buffer().size() * sizeof(kernel::FusionPixel);
  for (const auto& [key, block] : host_blocks_) m.host_bytes += sizeof(BlockData) + block.voxels.size() * sizeof(Voxel) + sizeof(key);
  return m;
}

std::vector<Eigen::Vector3i> TsdfVolume::block_coords() const {
  std::vector<Eigen::Vector3i> out;
  for (uint64_t k : download_prefix(block_keys_, num_blocks_)) out.push_back(block_coord(k));
  return out;
}

std::vector<Eigen::Vector3i> TsdfVolume::changed_blocks(uint64_t since) const {
  const auto keys = download_prefix(block_keys_, num_blocks_);
  const auto versions = download_prefix(block_versions_, num_blocks_);
  std::vector<Eigen::Vector3i> out;
  for (size_t i = 0; i < keys.size(); ++i)
    if (versions[i] > since) out.push_back(block_coord(keys[i]));
  std::vector<uint64_t> host;
  for (const auto& [key, block] : host_blocks_)
    if (block.version > since) host.push_back(key);
  std::sort(host.begin(), host.end());
  for (uint64_t k : host) out.push_back(block_coord(k));
  return out;
}

std::optional<BlockData> TsdfVolume::read_block(const Eigen::Vector3i& coord) const {
  const uint64_t key = block_key(coord.x(), coord.y(), coord.z());
  if (auto it = host_blocks_.find(key); it != host_blocks_.end()) return it->second;
  const auto keys = download_prefix(block_keys_, num_blocks_);
  const auto it = std::find(keys.begin(), keys.end(), key);
  if (it == keys.end()) return std::nullopt;
  const size_t i = size_t(it - keys.begin());
  BlockData b{coord, 0, {}};
  const int32_t slot = int32_t(i);
  download_blocks(std::span(&slot, 1), [&](size_t, std::span<const Voxel> v) { b.voxels.assign(v.begin(), v.end()); });
  mem::copy(&b.version, Device::cpu(), block_versions_.data() + i, device_, sizeof(uint64_t));
  return b;
}

std::vector<BlockData> TsdfVolume::read_all_blocks() const {
  const auto keys = download_prefix(block_keys_, num_blocks_);
  const auto versions = download_prefix(block_versions_, num_blocks_);
  std::vector<int32_t> all(static_cast<size_t>(num_blocks_));
  std::iota(all.begin(), all.end(), 0);
  std::vector<BlockData> out;
  out.reserve(keys.size() + host_blocks_.size());
  download_blocks(all, [&](size_t i, std::span<const Voxel> v) {
    out.push_back({block_coord(keys[i]), versions[i], std::vector<Voxel>(v.begin(), v.end())});
  });
  for (const auto& [key, block] : host_blocks_) out.push_back(block);
  std::sort(out.begin(), out.end(), [](const BlockData& a, const BlockData& b) {
    return block_key(a.coord.x(), a.coord.y(), a.coord.z()) < block_key(b.coord.x(), b.coord.y(), b.coord.z());
  });
  return out;
}

void TsdfVolume::ensure_pool(int64_t blocks) {
  const int64_t capacity = pool_capacity();
  if (blocks <= capacity) return;
  const int64_t bigger = std::max(blocks, capacity + capacity / 2);
  spdlog::debug("tsdf: block pool {} -> {} blocks", capacity, bigger);
  resize_pool(bigger);
}

void TsdfVolume::shrink_pool(int64_t blocks) {
  const int64_t smaller = std::max({blocks, num_blocks_, int64_t(1)});
  if (smaller >= pool_capacity()) return;
  spdlog::debug("tsdf: block pool {} -> {} blocks", pool_capacity(), smaller);
  resize_pool(smaller);
}

void TsdfVolume::resize_pool(int64_t capacity) {
  resize_keep(geometry_, capacity * kBlockVoxels, num_blocks_ * kBlockVoxels, device_);
  resize_keep(attributes_, capacity * kBlockVoxels, num_blocks_ * kBlockVoxels, device_);
  zero_range(geometry_, num_blocks_ * kBlockVoxels, capacity * kBlockVoxels, device_);
  zero_range(attributes_, num_blocks_ * kBlockVoxels, capacity * kBlockVoxels, device_);
  resize_keep(block_keys_, capacity, num_blocks_, device_);
  resize_keep(block_versions_, capacity, num_blocks_, device_);
  resize_keep(block_stamps_, capacity, num_blocks_, device_);
  resize_keep(crossing_boxes_, capacity, num_blocks_, device_);
  zero_range(crossing_boxes_, num_blocks_, capacity, device_);
  resize_keep(active_, capacity, std::min(capacity, int64_t(active_.size())), device_);
}

void TsdfVolume::rehash(int64_t capacity) {
  capacity = next_pow2(std::max<int64_t>(capacity, 2 * num_blocks_ + 1));
  for (;;) {
    hash_keys_ = Buffer<uint64_t>(size_t(capacity), device_);
    hash_values_ = Buffer<int32_t>(size_t(capacity), device_);
    const kernel::HashView h = hash_view();
    RRG_DISPATCH(device_, kernel::clear_hash_cpu(h), kernel::clear_hash_cuda(h));
    counters_.fill_zero();
    const Span<const uint64_t> keys = block_keys();
    int32_t* failed = counters_.data();
    RRG_DISPATCH(device_, kernel::insert_known_cpu(h, keys, 0, failed),
                 kernel::insert_known_cuda(h, keys, 0, failed));
    const int32_t n_failed = download_prefix(counters_, 1)[0];
    if (n_failed == 0) break;
    spdlog::info("tsdf: rehash into {} slots left {} blocks without a slot; growing", capacity, n_failed);
    capacity *= 2;
  }
  new_keys_ = Buffer<uint64_t>(size_t(capacity), device_);
  new_slots_ = Buffer<int32_t>(size_t(capacity), device_);
}

void TsdfVolume::grow_hash_for(int64_t blocks) {
  if (2 * blocks > hash_capacity()) {
    const int64_t capacity = next_pow2(4 * blocks);
    spdlog::debug("tsdf: hash {} -> {} slots for {} blocks", hash_capacity(), capacity, blocks);
    rehash(capacity);
  }
}

Span<const int32_t> TsdfVolume::allocate_from_depth(const DeviceImage<float>& depth, const Intrinsics& K,
                                                    const Eigen::Matrix3f& R_wc, const Eigen::Vector3f& t_wc) {
  ++version_;
  std::vector<int32_t> counts;
  for (;;) {
    ++pass_id_;
    counters_.fill_zero();
    kernel::TouchArgs a{depth.view(), K, R_wc, t_wc, params_.voxel_size, params_.band(),
                        params_.min_depth, params_.max_depth, hash_view(),
                        {block_stamps_.data(), num_blocks_}, pass_id_, new_keys_.span(), new_slots_.span(),
                        {active_.data(), num_blocks_}, counters_.data()};
    RRG_DISPATCH(device_, kernel::touch_blocks_cpu(a), kernel::touch_blocks_cuda(a));
    counts = download_prefix(counters_, 3);
    if (counts[2] == 0) break;
    // Never drop a block: the pass runs again on a table twice as big (pending inserts are dropped
    // by the rehash, and the new pass id lists every touched block afresh).
    spdlog::debug("tsdf: hash table of {} slots full for {} block inserts; growing to {}", hash_capacity(),
                  counts[2], 4 * hash_capacity());
    rehash(4 * hash_capacity());
  }
  const int64_t n_new = counts[0], n_active = counts[1];
  if (n_new > 0) {
    std::vector<uint64_t> keys = download_prefix(new_keys_, n_new);
    const std::vector<int32_t> slots32 = download_prefix(new_slots_, n_new);
    std::vector<size_t> order(static_cast<size_t>(n_new));
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return keys[a] < keys[b]; });
    std::vector<uint64_t> sorted_keys(order.size());
    std::vector<int64_t> sorted_slots(order.size());
    std::vector<const BlockData*> restored(order.size(), nullptr);
    for (size_t j = 0; j < order.size(); ++j) {
      sorted_keys[j] = keys[order[j]];
      sorted_slots[j] = slots32[order[j]];
      if (auto it = host_blocks_.find(sorted_keys[j]); it != host_blocks_.end()) restored[j] = &it->second;
    }
    append_blocks(sorted_keys, sorted_slots, restored, n_active);
  }
  grow_hash_for(num_blocks_);
  return {active_.data(), n_active + n_new};
}

void TsdfVolume::append_blocks(std::span<const uint64_t> keys, std::span<const int64_t> slots,
                               std::span<const BlockData* const> restored, int64_t active_offset) {
  const int64_t n = int64_t(keys.size()), first = num_blocks_;
  ensure_pool(first + n);
  const auto keys_d = Buffer<uint64_t>::from_host(keys, device_);
  std::vector<int32_t> slots32(slots.begin(), slots.end());
  const auto slots_d = Buffer<int32_t>::from_host(slots32, device_);
  const int64_t capacity = int64_t(block_keys_.size());
  kernel::AppendArgs a{hash_view(), keys_d.span(), slots_d.span(), int32_t(first),
                       block_keys_.span(), block_versions_.span(), block_stamps_.span(), pass_id_, version_,
                       {active_.data(), capacity}, int32_t(active_offset)};
  RRG_DISPATCH(device_, kernel::append_blocks_cpu(a), kernel::append_blocks_cuda(a));
  num_blocks_ += n;
  // Blocks coming back from host memory: their voxels replace the zeros of the free slots.
  std::vector<int32_t> index;
  std::vector<const BlockData*> back;
  for (int64_t j = 0; j < n; ++j) {
    if (!restored[size_t(j)]) continue;
    index.push_back(int32_t(first + j));
    back.push_back(restored[size_t(j)]);
  }
  if (!index.empty()) {
    upload_blocks(index, [&](size_t j) { return std::span<const Voxel>(back[j]->voxels); });
    for (int64_t j = 0; j < n; ++j)
      if (restored[size_t(j)]) host_blocks_.erase(keys[size_t(j)]);
    spdlog::debug("tsdf: {} blocks streamed back in", index.size());
  }
}

void TsdfVolume::insert_blocks(std::span<const BlockData> blocks) {
  std::vector<const BlockData*> ptrs;
  ptrs.reserve(blocks.size());
  for (const BlockData& b : blocks) ptrs.push_back(&b);
  insert_block_ptrs(ptrs);
}

std::vector<uint64_t> TsdfVolume::keys_of_new_blocks(std::span<const BlockData* const> blocks, const char* who) const {
  const auto existing = download_prefix(block_keys_, num_blocks_);
  std::vector<uint64_t> present(existing);
  std::sort(present.begin(), present.end());
  std::vector<uint64_t> keys;
  keys.reserve(blocks.size());
  for (const BlockData* b : blocks) {
    if (!block_in_range(b->coord.x(), b->coord.y(), b->coord.z()) || b->voxels.size() != size_t(kBlockVoxels))
      throw std::invalid_argument(std::string("TsdfVolume::") + who + ": block out of range or not 512 voxels");
    const uint64_t key = block_key(b->coord.x(), b->coord.y(), b->coord.z());
    if (std::binary_search(present.begin(), present.end(), key))
      throw std::invalid_argument(std::string("TsdfVolume::") + who + ": block already present");
    keys.push_back(key);
  }
  return keys;
}

void TsdfVolume::insert_host_blocks(std::vector<BlockData> blocks) {
  if (blocks.empty()) return;
  std::vector<const BlockData*> ptrs;
  ptrs.reserve(blocks.size());
  for (const BlockData& b : blocks) ptrs.push_back(&b);
  const std::vector<uint64_t> keys = keys_of_new_blocks(ptrs, "insert_host_blocks");
  for (uint64_t key : keys)
    if (host_blocks_.count(key)) throw std::invalid_argument("TsdfVolume::insert_host_blocks: block already present");
  std::vector<uint64_t> sorted(keys);
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    throw std::invalid_argument("TsdfVolume::insert_host_blocks: block listed twice");
  for (size_t j = 0; j < blocks.size(); ++j) host_blocks_.emplace(keys[j], std::move(blocks[j]));
}

void TsdfVolume::insert_block_ptrs(std::span<const BlockData* const> blocks) {
  if (blocks.empty()) return;
  const int64_t n = int64_t(blocks.size()), first = num_blocks_;
  const std::vector<uint64_t> keys = keys_of_new_blocks(blocks, "insert_blocks");
  std::vector<uint64_t> versions;
  versions.reserve(blocks.size());
  for (const BlockData* b : blocks) versions.push_back(b->version);
  ensure_pool(first + n);
  mem::copy(block_keys_.data() + first, device_, keys.data(), Device::cpu(), keys.size() * sizeof(uint64_t));
  mem::copy(block_versions_.data() + first, device_, versions.data(), Device::cpu(), versions.size() * sizeof(uint64_t));
  mem::fill_zero(block_stamps_.data() + first, size_t(n) * sizeof(int32_t), device_);
  num_blocks_ += n;
  std::vector<int32_t> index(static_cast<size_t>(n));
  std::iota(index.begin(), index.end(), int32_t(first));
  upload_blocks(index, [&](size_t j) { return std::span<const Voxel>(blocks[j]->voxels); });
  rehash(std::max(hash_capacity(), next_pow2(4 * num_blocks_)));
}

int64_t TsdfVolume::stream_out(const Eigen::Vector3f& center, float radius) {
  return stream_out_where([&](uint64_t key) {
    return (block_center(block_coord(key), params_.voxel_size) - center).norm() > radius;
  });
}

int64_t TsdfVolume::stream_out(std::span<const Eigen::Vector3i> blocks) {
  std::vector<uint64_t> listed;
  listed.reserve(blocks.size());
  for (const auto& c : blocks)
    if (block_in_range(c.x(), c.y(), c.z())) listed.push_back(block_key(c.x(), c.y(), c.z()));
  std::sort(listed.begin(), listed.end());
  return stream_out_where([&](uint64_t key) { return std::binary_search(listed.begin(), listed.end(), key); });
}

template <class Leave>
int64_t TsdfVolume::stream_out_where(Leave leave) {
  const auto keys = download_prefix(block_keys_, num_blocks_);
  const auto versions = download_prefix(block_versions_, num_blocks_);
  std::vector<int32_t> out;  // ascending
  for (int64_t i = 0; i < num_blocks_; ++i)
    if (leave(keys[size_t(i)])) out.push_back(int32_t(i));
  if (out.empty()) return 0;
  download_blocks(out, [&](size_t j, std::span<const Voxel> v) {
    const uint64_t key = keys[size_t(out[j])];
    host_blocks_[key] = BlockData{block_coord(key), versions[size_t(out[j])], std::vector<Voxel>(v.begin(), v.end())};
  });
  // Compact the pool: the kept blocks in its tail fill the slots the leaving blocks free in front,
  // so the work is in proportion to the blocks moved, not to the pool. Then rebuild the hash.
  const int64_t kept = num_blocks_ - int64_t(out.size());
  std::vector<int32_t> holes, movers;
  for (int32_t i : out)
    if (i < kept) holes.push_back(i);
  for (int64_t i = kept, j = 0; i < num_blocks_; ++i) {
    while (j < int64_t(out.size()) && out[size_t(j)] < i) ++j;
    if (j == int64_t(out.size()) || out[size_t(j)] != i) movers.push_back(int32_t(i));
  }
  std::vector<uint64_t> kept_keys(keys.begin(), keys.begin() + kept), kept_versions(versions.begin(), versions.begin() + kept);
  for (size_t j = 0; j < holes.size(); ++j) {
    kept_keys[size_t(holes[j])] = keys[size_t(movers[j])];
    kept_versions[size_t(holes[j])] = versions[size_t(movers[j])];
  }
  move_blocks(movers, holes);
  zero_range(geometry_, kept * kBlockVoxels, num_blocks_ * kBlockVoxels, device_);
  zero_range(attributes_, kept * kBlockVoxels, num_blocks_ * kBlockVoxels, device_);
  zero_range(crossing_boxes_, kept, num_blocks_, device_);
  num_blocks_ = kept;
  if (num_blocks_ > 0) {
    mem::copy(block_keys_.data(), device_, kept_keys.data(), Device::cpu(), kept_keys.size() * sizeof(uint64_t));
    mem::copy(block_versions_.data(), device_, kept_versions.data(), Device::cpu(), kept_versions.size() * sizeof(uint64_t));
  }
  block_stamps_.fill_zero();
  rehash(hash_capacity());
  spdlog::debug("tsdf: {} blocks streamed out ({} resident)", out.size(), num_blocks_);
  return int64_t(out.size());
}

int64_t TsdfVolume::stream_in(const Eigen::Vector3f& center, float radius) {
  std::vector<const BlockData*> back;
  for (const auto& [key, block] : host_blocks_)
    if ((block_center(block.coord, params_.voxel_size) - center).norm() <= radius) back.push_back(&block);
  return stream_in_blocks(std::move(back));
}

std::vector<Eigen::Vector3i> TsdfVolume::host_blocks_where(const std::function<bool(const Eigen::Vector3i&)>& keep) const {
  std::vector<uint64_t> keys;
  for (const auto& [key, block] : host_blocks_)
    if (keep(block.coord)) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  std::vector<Eigen::Vector3i> out;
  out.reserve(keys.size());
  for (uint64_t k : keys) out.push_back(block_coord(k));
  return out;
}

int64_t TsdfVolume::stream_in(std::span<const Eigen::Vector3i> blocks) {
  std::vector<const BlockData*> back;
  for (const auto& c : blocks) {
    if (!block_in_range(c.x(), c.y(), c.z())) continue;
    if (auto it = host_blocks_.find(block_key(c.x(), c.y(), c.z())); it != host_blocks_.end()) back.push_back(&it->second);
  }
  return stream_in_blocks(std::move(back));
}

int64_t TsdfVolume::stream_in_blocks(std::vector<const BlockData*> back) {
  // The host copies are dropped only once the blocks are in the pool: nothing is lost if that throws.
  const auto key_of = [](const BlockData* b) { return block_key(b->coord.x(), b->coord.y(), b->coord.z()); };
  std::sort(back.begin(), back.end(), [&](const BlockData* a, const BlockData* b) { return key_of(a) < key_of(b); });
  back.erase(std::unique(back.begin(), back.end()), back.end());
  insert_block_ptrs(back);
  for (const BlockData* b : back) host_blocks_.erase(key_of(b));  // the key is read before b goes
  return int64_t(back.size());
}

std::vector<Eigen::Vector3i> TsdfVolume::host_block_coords() const {
  return host_blocks_where([](const Eigen::Vector3i&) { return true; });
}

kernel::PoolView TsdfVolume::pool() { return {geometry_.span(), attributes_.span()}; }

template <class Sink>
void TsdfVolume::download_blocks(std::span<const int32_t> slots, Sink&& sink) const {
  if (slots.empty()) return;
  Buffer<Voxel> stage(std::min(slots.size(), kTransferBlocks) * kBlockVoxels, device_);
  std::vector<Voxel> host(stage.size());
  for (size_t start = 0; start < slots.size(); start += kTransferBlocks) {
    const auto chunk = slots.subspan(start, std::min(kTransferBlocks, slots.size() - start));
    gather_records(chunk, stage);
    mem::copy(host.data(), Device::cpu(), stage.data(), device_, chunk.size() * kBlockVoxels * sizeof(Voxel));
    for (size_t j = 0; j < chunk.size(); ++j)
      sink(start + j, std::span<const Voxel>(host).subspan(j * kBlockVoxels, kBlockVoxels));
  }
}

template <class Source>
void TsdfVolume::upload_blocks(std::span<const int32_t> slots, Source&& source) {
  if (slots.empty()) return;
  Buffer<Voxel> stage(std::min(slots.size(), kTransferBlocks) * kBlockVoxels, device_);
  std::vector<Voxel> host(stage.size());
  for (size_t start = 0; start < slots.size(); start += kTransferBlocks) {
    const auto chunk = slots.subspan(start, std::min(kTransferBlocks, slots.size() - start));
    for (size_t j = 0; j < chunk.size(); ++j) {
      const std::span<const Voxel> v = source(start + j);
      std::copy(v.begin(), v.end(), host.begin() + std::ptrdiff_t(j * kBlockVoxels));
    }
    mem::copy(stage.data(), device_, host.data(), Device::cpu(), chunk.size() * kBlockVoxels * sizeof(Voxel));
    scatter_records(stage, chunk);
  }
}

void TsdfVolume::move_blocks(std::span<const int32_t> from, std::span<const int32_t> to) {
  if (from.empty()) return;
  Buffer<Voxel> stage(std::min(from.size(), kTransferBlocks) * kBlockVoxels, device_);
  for (size_t start = 0; start < from.size(); start += kTransferBlocks) {
    const size_t m = std::min(kTransferBlocks, from.size() - start);
    gather_records(from.subspan(start, m), stage);
    scatter_records(stage, to.subspan(start, m));
  }
}

void TsdfVolume::gather_records(std::span<const int32_t> index, Buffer<Voxel>& records) const {
  if (index.empty()) return;
  const auto index_d = Buffer<int32_t>::from_host(index, device_);
  const kernel::PoolView p = const_cast<TsdfVolume&>(*this).pool();  // read only
  const Span<const int32_t> idx = index_d.span();
  RRG_DISPATCH(device_, kernel::gather_blocks_cpu(p, idx, records.span()),
               kernel::gather_blocks_cuda(p, idx, records.span()));
}

void TsdfVolume::scatter_records(const Buffer<Voxel>& records, std::span<const int32_t> index) {
  if (index.empty()) return;
  const auto index_d = Buffer<int32_t>::from_host(index, device_);
  const Span<const Voxel> src = records.span();
  const Span<const int32_t> idx = index_d.span();
  RRG_DISPATCH(device_, kernel::scatter_blocks_cpu(src, idx, pool()), kernel::scatter_blocks_cuda(src, idx, pool()));
  update_crossing_boxes(idx);
}

void TsdfVolume::update_crossing_boxes(Span<const int32_t> blocks) {
  // Over the whole pool: while stream_out compacts it, written slots may lie beyond num_blocks_.
  const Span<const TsdfVoxel> g = geometry_.span();
  const Span<uint32_t> boxes = crossing_boxes_.span();
  RRG_DISPATCH(device_, kernel::update_crossing_boxes_cpu(g, blocks, boxes),
               kernel::update_crossing_boxes_cuda(g, blocks, boxes));
}

int64_t TsdfVolume::stream_in_all() {
  return stream_in(Eigen::Vector3f::Zero(), std::numeric_limits<float>::infinity());
}

}  // namespace rrg
