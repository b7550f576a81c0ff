#pragma once
// Reading the volume at world points: voxel lookup through the hash (with a one-block cache) and
// trilinear interpolation over the 8 voxels around a point. Shared by raycasting and tests.
#include "core/tsdf/voxel_hash_device.h"

#include <Eigen/Core>

#include <cmath>

namespace rrg::kernel {

struct VolumeView {
  HashView hash;
  Span<const TsdfVoxel> geometry;    // [blocks * 512]
  Span<const AttrVoxel> attributes;  // [blocks * 512]
  float voxel_size;
};

// The last few blocks looked up, so that a ray's samples (and the ± offsets of a normal's central
// differences, which straddle block borders) probe the hash table once per block, not per sample.
struct BlockCache {
  static constexpr int kEntries = 4;  // a power of two
  uint64_t key[kEntries] = {kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey};
  int32_t block[kEntries] = {-1, -1, -1, -1};
  int next = 0;
};

// Pool index of the block with coordinates (bx, by, bz), or -1 when it is not resident.
RRG_HD inline int32_t cached_block(const VolumeView& vol, int bx, int by, int bz, BlockCache& cache) {
  if (!block_in_range(bx, by, bz)) return -1;
  const uint64_t key = block_key(bx, by, bz);
  for (int e = 0; e < BlockCache::kEntries; ++e)
    if (cache.key[e] == key) return cache.block[e];
  const int32_t b = hash_find(vol.hash, key);
  cache.key[cache.next] = key;
  cache.block[cache.next] = b;
  cache.next = (cache.next + 1) & (BlockCache::kEntries - 1);
  return b;
}

// Pool index of the voxel with global coordinates g (centre at g · s), or -1 when its block is not
// resident.
RRG_HD inline int64_t voxel_at(const VolumeView& vol, const Eigen::Vector3i& g, BlockCache& cache) {
  const int32_t b = cached_block(vol, block_of(g.x()), block_of(g.y()), block_of(g.z()), cache);
  if (b < 0) return -1;
  return int64_t(b) * kBlockVoxels + local_index(local_of(g.x()), local_of(g.y()), local_of(g.z()));
}

// The 8 voxels around p (pool indices) and their trilinear weights w_i; false when one is missing
// or unobserved.
struct Corners {
  int64_t v[8];
  float w[8];
};
RRG_HD inline bool trilinear_corners(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache,
                                     Corners& out) {
  const Eigen::Vector3f q = p_w / vol.voxel_size;
  const Eigen::Vector3f b(floorf(q.x()), floorf(q.y()), floorf(q.z()));
  const Eigen::Vector3f f = q - b;
  const Eigen::Vector3i base(int(b.x()), int(b.y()), int(b.z()));
  const int lx = local_of(base.x()), ly = local_of(base.y()), lz = local_of(base.z());
  // The corners lie in the base voxel's block and, where a local coordinate is 7, in its +x / +y / +z
  // neighbours: each of those blocks is looked up once, through the cache.
  const bool ox = lx == kBlockSide - 1, oy = ly == kBlockSide - 1, oz = lz == kBlockSide - 1;
  int64_t first[8] = {};  // voxel 0 of each neighbouring block (bit 0: +x, 1: +y, 2: +z)
  const int bx = block_of(base.x()), by = block_of(base.y()), bz = block_of(base.z());
  for (int o = 0; o < 8; ++o) {
    const int dx = o & 1, dy = (o >> 1) & 1, dz = o >> 2;
    if ((dx && !ox) || (dy && !oy) || (dz && !oz)) continue;
    const int32_t b = cached_block(vol, bx + dx, by + dy, bz + dz, cache);
    if (b < 0) return false;
    first[o] = int64_t(b) * kBlockVoxels;
  }
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const int x = lx + dx, y = ly + dy, z = lz + dz;
    const int o = (x >> 3) | ((y >> 3) << 1) | ((z >> 3) << 2);
    const int64_t v = first[o] + local_index(x & 7, y & 7, z & 7);
    if (vol.geometry[v].weight == 0) return false;
    out.v[c] = v;
    out.w[c] = (dx ? f.x() : 1.0f - f.x()) * (dy ? f.y() : 1.0f - f.y()) * (dz ? f.z() : 1.0f - f.z());
  }
  return true;
}

// Normalised TSDF d/ε at p (trilinear); false where not all 8 voxels are observed.
RRG_HD inline bool sample_tsdf(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache, float& out) {
  Corners c;
  if (!trilinear_corners(vol, p_w, cache, c)) return false;
  float f = 0.0f;
  for (int i = 0; i < 8; ++i) f += c.w[i] * voxel_codec::decode_tsdf(vol.geometry[c.v[i]].tsdf);
  out = f;
  return true;
}

}  // namespace rrg::kernel
