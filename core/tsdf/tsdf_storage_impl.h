#pragma once
// Kernels of the volume's storage (tsdf_volume.cpp): block allocation from depth, assignment of new
// blocks, rehash, block gather / scatter. Bodies templated on the back-end tag; instantiated by
// tsdf_storage_cpu.cpp and tsdf_storage_cuda.cu.
#include "core/common/camera.h"
#include "core/tsdf/crossing_box_device.h"
#include "core/tsdf/truncation_band.h"
#include "core/tsdf/voxel_hash_device.h"

#include <Eigen/Core>

#include <cmath>

namespace rrg::kernel {

struct TouchArgs {
  ImageView<const float> depth;
  Intrinsics K;
  Eigen::Matrix3f R_wc;
  Eigen::Vector3f t_wc;
  float voxel_size;
  TruncationBand band;       // ε(d)
  float min_depth, max_depth;
  HashView hash;
  Span<int32_t> stamps;      // [blocks] last pass that listed the block active
  int32_t pass_id;
  Span<uint64_t> new_keys;   // [hash capacity] keys this pass inserted
  Span<int32_t> new_slots;   // [hash capacity] their slots
  Span<int32_t> active;      // [blocks] existing blocks touched this pass
  int32_t* counters;         // [3] new, active, failed inserts
};

// Visits the blocks crossed by the segment a -> b (block units: block = floor(q)), Amanatides-Woo.
template <class F>
RRG_HD void for_blocks_on_segment(const Eigen::Vector3f& a, const Eigen::Vector3f& b, F visit) {
  Eigen::Vector3i cell(floor_to_int(a.x()), floor_to_int(a.y()), floor_to_int(a.z()));
  const Eigen::Vector3i last(floor_to_int(b.x()), floor_to_int(b.y()), floor_to_int(b.z()));
  const Eigen::Vector3f d = b - a;
  Eigen::Vector3i step;
  Eigen::Vector3f t_max, t_delta;
  for (int k = 0; k < 3; ++k) {
    step[k] = d[k] > 0.0f ? 1 : (d[k] < 0.0f ? -1 : 0);
    if (step[k] == 0) {
      t_max[k] = 2.0f;
      t_delta[k] = 2.0f;
    } else {
      const float boundary = step[k] > 0 ? float(cell[k] + 1) : float(cell[k]);
      t_max[k] = (boundary - a[k]) / d[k];
      t_delta[k] = float(step[k]) / d[k];
    }
  }
  const int max_steps = abs(last.x() - cell.x()) + abs(last.y() - cell.y()) + abs(last.z() - cell.z());
  visit(cell);
  for (int i = 0; i < max_steps; ++i) {
    int k = 0;
    if (t_max[1] < t_max[k]) k = 1;
    if (t_max[2] < t_max[k]) k = 2;
    if (t_max[k] > 1.0f) break;
    cell[k] += step[k];
    t_max[k] += t_delta[k];
    visit(cell);
  }
}

inline constexpr int kTouchRun = 8;    // pixels of a row per work item of touch_blocks
inline constexpr int kTouchCache = 8;  // recent block keys a work item remembers

// Per valid depth pixel: every block on its ray within [d - ε(d), d + ε(d)] is found or inserted
// (truncation_band.h). A work item takes a run of kTouchRun pixels of one row: neighbouring pixels
// cross mostly the same blocks (a 4 cm block spans ~10 pixels at 2 m), so a key met again within
// the run is skipped instead of probing the hash table and its atomics again.
template <class Backend>
void touch_blocks(Backend backend, const TouchArgs& a) {
  const TouchArgs args = a;
  const int w = a.depth.width;
  const int runs_per_row = (w + kTouchRun - 1) / kTouchRun;
  parallel_for(backend, int64_t(runs_per_row) * a.depth.height, [=] RRG_HD(int64_t item) {
    const int y = int(item / runs_per_row), x0 = int(item % runs_per_row) * kTouchRun;
    const int x1 = x0 + kTouchRun < w ? x0 + kTouchRun : w;
    uint64_t recent[kTouchCache];
    for (int k = 0; k < kTouchCache; ++k) recent[k] = kEmptyKey;
    int next = 0;
    const float to_block = 1.0f / (args.voxel_size * kBlockSide);
    const float half = 0.5f / kBlockSide;  // voxel g covers [g - 1/2, g + 1/2) voxel units
    for (int x = x0; x < x1; ++x) {
      const float d = args.depth(x, y);
      if (!(d >= args.min_depth && d <= args.max_depth)) continue;
      const float eps = args.band.at(d);
      const float d0 = max_f(d - eps, 1e-3f), d1 = d + eps;
      const Eigen::Vector3f p0 = args.R_wc * args.K.unproject(float(x), float(y), d0) + args.t_wc;
      const Eigen::Vector3f p1 = args.R_wc * args.K.unproject(float(x), float(y), d1) + args.t_wc;
      const Eigen::Vector3f q0 = p0 * to_block + Eigen::Vector3f::Constant(half);
      const Eigen::Vector3f q1 = p1 * to_block + Eigen::Vector3f::Constant(half);
      for_blocks_on_segment(q0, q1, [&](const Eigen::Vector3i& c) {
        if (!block_in_range(c.x(), c.y(), c.z())) return;
        const uint64_t key = block_key(c.x(), c.y(), c.z());
        for (int k = 0; k < kTouchCache; ++k)
          if (recent[k] == key) return;
        int64_t slot = 0;
        const InsertResult r = hash_insert(args.hash, key, slot);
        if (r == InsertResult::Inserted) {
          const int32_t k = atomic_add(&args.counters[0], int32_t{1});
          args.new_keys[k] = key;
          args.new_slots[k] = int32_t(slot);
        } else if (r == InsertResult::Found) {
          const int32_t block = args.hash.values[slot];
          if (block >= 0 && atomic_max(&args.stamps[block], args.pass_id) < args.pass_id)
            args.active[atomic_add(&args.counters[1], int32_t{1})] = block;
        } else {
          atomic_add(&args.counters[2], int32_t{1});
          return;  // not remembered: a later pixel must count the failure too
        }
        recent[next] = key;
        next = (next + 1) % kTouchCache;
      });
    }
  });
}

struct AppendArgs {
  HashView hash;
  Span<const uint64_t> keys;   // [n] new keys, sorted
  Span<const int32_t> slots;   // [n] their hash slots
  int32_t first_block;         // key j becomes block first_block + j
  Span<uint64_t> block_keys;
  Span<uint64_t> block_versions;
  Span<int32_t> stamps;
  int32_t pass_id;
  uint64_t version;
  Span<int32_t> active;        // new blocks are listed at active[active_offset + j] (if >= 0)
  int32_t active_offset;
};

template <class Backend>
void append_blocks(Backend backend, const AppendArgs& a) {
  const AppendArgs args = a;
  parallel_for(backend, a.keys.size, [=] RRG_HD(int64_t j) {
    const int32_t block = args.first_block + int32_t(j);
    args.hash.values[args.slots[j]] = block;
    args.block_keys[block] = args.keys[j];
    args.block_versions[block] = args.version;
    args.stamps[block] = args.pass_id;
    if (args.active_offset >= 0) args.active[args.active_offset + j] = block;
  });
  // The new blocks' voxels are already zero: TsdfVolume keeps free pool slots zeroed.
}

template <class Backend>
void clear_hash(Backend backend, HashView h) {
  parallel_for(backend, h.keys.size, [=] RRG_HD(int64_t i) {
    h.keys[i] = kEmptyKey;
    h.values[i] = -1;
  });
}

// Inserts keys[j] (distinct, absent) with value first + j; counts failures in failed[0].
template <class Backend>
void insert_known(Backend backend, HashView h, Span<const uint64_t> keys, int32_t first, int32_t* failed) {
  parallel_for(backend, keys.size, [=] RRG_HD(int64_t j) {
    int64_t slot = 0;
    if (hash_insert(h, keys[j], slot) == InsertResult::Inserted)
      h.values[slot] = first + int32_t(j);
    else
      atomic_add(failed, int32_t{1});
  });
}

// The block pool's two voxel layers (voxel.h).
struct PoolView {
  Span<TsdfVoxel> geometry;
  Span<AttrVoxel> attributes;
};

// records block j = pool block index[j], as whole Voxel records (gather).
template <class Backend>
void gather_blocks(Backend backend, PoolView pool, Span<const int32_t> index, Span<Voxel> records) {
  parallel_for(backend, index.size * kBlockVoxels, [=] RRG_HD(int64_t i) {
    const int64_t b = index[i / kBlockVoxels], v = i % kBlockVoxels;
    records[i] = join_voxel(pool.geometry[b * kBlockVoxels + v], pool.attributes[b * kBlockVoxels + v]);
  });
}

// pool block index[j] = records block j (scatter).
template <class Backend>
void scatter_blocks(Backend backend, Span<const Voxel> records, Span<const int32_t> index, PoolView pool) {
  parallel_for(backend, index.size * kBlockVoxels, [=] RRG_HD(int64_t i) {
    const int64_t b = index[i / kBlockVoxels], v = i % kBlockVoxels;
    pool.geometry[b * kBlockVoxels + v] = voxel_geometry(records[i]);
    pool.attributes[b * kBlockVoxels + v] = voxel_attributes(records[i]);
  });
}

// boxes[b] ← the crossing box code of block b for each b in `blocks` (crossing_box_device.h).
template <class Backend>
void update_crossing_boxes(Backend backend, Span<const TsdfVoxel> geometry, Span<const int32_t> blocks,
                           Span<uint32_t> boxes) {
  parallel_for(backend, blocks.size, [=] RRG_HD(int64_t j) {
    const int32_t b = blocks[j];
    boxes[b] = encode_crossing_box(geometry, b);
  });
}

void touch_blocks_cpu(const TouchArgs& a);
void touch_blocks_cuda(const TouchArgs& a);
void append_blocks_cpu(const AppendArgs& a);
void append_blocks_cuda(const AppendArgs& a);
void clear_hash_cpu(HashView h);
void clear_hash_cuda(HashView h);
void insert_known_cpu(HashView h, Span<const uint64_t> keys, int32_t first, int32_t* failed);
void insert_known_cuda(HashView h, Span<const uint64_t> keys, int32_t first, int32_t* failed);
void gather_blocks_cpu(PoolView pool, Span<const int32_t> index, Span<Voxel> records);
void gather_blocks_cuda(PoolView pool, Span<const int32_t> index, Span<Voxel> records);
void scatter_blocks_cpu(Span<const Voxel> records, Span<const int32_t> index, PoolView pool);
void scatter_blocks_cuda(Span<const Voxel> records, Span<const int32_t> index, PoolView pool);

void update_crossing_boxes_cpu(Span<const TsdfVoxel> geometry, Span<const int32_t> blocks, Span<uint32_t> boxes);
void update_crossing_boxes_cuda(Span<const TsdfVoxel> geometry, Span<const int32_t> blocks, Span<uint32_t> boxes);

}  // namespace rrg::kernel
