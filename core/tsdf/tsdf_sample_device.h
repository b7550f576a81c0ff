#pragma once
// Reading the volume at world points: block lookup through the hash (with a small per-ray block
// cache) and trilinear interpolation over the 8 voxels around a point. Shared by raycasting and tests.
#include "core/common/fast_math.h"
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

// The blocks a ray has looked up, so that its samples (and the ± offsets of a normal's central
// differences, which straddle block borders) probe the hash table once per block, not per sample.
// Direct-mapped on the parity of the block coordinates: the 2 × 2 × 2 blocks around any block
// border (all a straddling cell or a shading neighbourhood touches) land in 8 distinct slots, so
// they never evict each other, and a lookup is one compare at a computed slot. (A 4-entry cache
// searched in order, kept most-recent-first, cost a quarter of the march's mispredicted branches:
// the entry that matched moved from sample to sample; callgrind --branch-sim.)
struct BlockCache {
  static constexpr int kEntries = 8;
  uint64_t key[kEntries] = {kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey};
  int32_t block[kEntries] = {-1, -1, -1, -1, -1, -1, -1, -1};
};

// Pool index of the block with coordinates (bx, by, bz), or -1 when it is not resident.
RRG_HD RRG_INLINE int32_t cached_block(const VolumeView& vol, int bx, int by, int bz, BlockCache& cache) {
  if (!block_in_range(bx, by, bz)) return -1;
  const uint64_t key = block_key(bx, by, bz);
  const int slot = (bx & 1) | ((by & 1) << 1) | ((bz & 1) << 2);
  if (cache.key[slot] != key) {
    cache.key[slot] = key;
    cache.block[slot] = hash_find(vol.hash, key);
  }
  return cache.block[slot];
}

// Trilinear sampling at p: the cell of p is the voxels g .. g + 1 with g = floor(p / s) (its lower
// corner), p = (g + f) · s with f in [0, 1)³.
enum class Sample {
  NoBlock,     // the block of the lower corner g is not resident: nothing valid nearby
  Unobserved,  // a corner is in a missing block or has weight 0
  Valid,
};

// The TSDF values of the 8 voxels around p (corner c = dx + 2 dy + 4 dz) in fixed-point units
// (d/ε × voxel_codec::kTsdfScale: scaled once after interpolating) and p's position f in the cell;
// for Sample::NoBlock only the coordinates of the missing block.
struct Corners {
  float t[8];
  Eigen::Vector3f f;
  Eigen::Vector3i block;
  int missing = 0;  // corners unobserved (weight 0); 8 means none of the cell's voxels is observed
};

RRG_HD RRG_INLINE Sample trilinear_corners(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache,
                                       Corners& out) {
  const Eigen::Vector3f q = p_w * (1.0f / vol.voxel_size);
  const int gx = floor_to_int(q.x()), gy = floor_to_int(q.y()), gz = floor_to_int(q.z());
  out.f = Eigen::Vector3f(q.x() - float(gx), q.y() - float(gy), q.z() - float(gz));
  const int lx = local_of(gx), ly = local_of(gy), lz = local_of(gz);
  const int bx = block_of(gx), by = block_of(gy), bz = block_of(gz);
  const int32_t b0 = cached_block(vol, bx, by, bz, cache);
  if (b0 < 0) {
    out.block = Eigen::Vector3i(bx, by, bz);
    return Sample::NoBlock;
  }
  const int64_t v0 = int64_t(b0) * kBlockVoxels + local_index(lx, ly, lz);
  // Axes along which the cell leaves the block (local coordinate 7): bit 0 x, 1 y, 2 z. One branch
  // on all three (the cell is in one block in (7/8)³ of the cases).
  const int crossing = ((lx + 1) >> 3) | (((ly + 1) >> 3) << 1) | (((lz + 1) >> 3) << 2);  // l + 1 = 8 ⟺ l = 7
  int missing = 0;
  if (crossing == 0) {
    // The whole cell in one block: fixed offsets from the lower corner.
    RRG_UNROLL
    for (int c = 0; c < 8; ++c) {
      const int64_t v = v0 + local_index(c & 1, (c >> 1) & 1, c >> 2);
      const TsdfVoxel g = vol.geometry[v];
      missing += int(g.weight == 0);
      out.t[c] = float(g.tsdf);
    }
    out.missing = missing;
    return missing ? Sample::Unobserved : Sample::Valid;
  }
  // The cell straddles blocks: where a local coordinate is 7, the corners one further lie in the
  // +x / +y / +z neighbour; each of those blocks is looked up once, through the cache.
  int64_t first[8] = {int64_t(b0) * kBlockVoxels};  // voxel 0 of each block (bit 0: +x, 1: +y, 2: +z)
  // The neighbours holding corners are the non-empty subsets of `crossing` (one block when a single
  // axis crosses, as in 87 % of the crossing cells): visited directly, with no test per neighbour.
  for (int o = crossing; o != 0; o = (o - 1) & crossing) {
    const int32_t b = cached_block(vol, bx + (o & 1), by + ((o >> 1) & 1), bz + (o >> 2), cache);
    if (b < 0) return Sample::Unobserved;
    first[o] = int64_t(b) * kBlockVoxels;
  }
  RRG_UNROLL
  for (int c = 0; c < 8; ++c) {
    const int x = lx + (c & 1), y = ly + ((c >> 1) & 1), z = lz + (c >> 2);
    const int o = (x >> 3) | ((y >> 3) << 1) | ((z >> 3) << 2);
    const int64_t v = first[o] + local_index(x & 7, y & 7, z & 7);
    const TsdfVoxel g = vol.geometry[v];
    missing += int(g.weight == 0);
    out.t[c] = float(g.tsdf);
  }
  out.missing = missing;
  return missing ? Sample::Unobserved : Sample::Valid;
}

// Trilinear weight of corner c at f.
RRG_HD inline float corner_weight(const Eigen::Vector3f& f, int c) {
  return ((c & 1) ? f.x() : 1.0f - f.x()) * ((c & 2) ? f.y() : 1.0f - f.y()) * ((c & 4) ? f.z() : 1.0f - f.z());
}

// The trilinear interpolant of the corner values at f (x, then y, then z).
RRG_HD inline float trilinear(const float t[8], const Eigen::Vector3f& f) {
  const auto lerp = [](float a, float b, float u) { return a + (b - a) * u; };
  const float y0 = lerp(lerp(t[0], t[1], f.x()), lerp(t[2], t[3], f.x()), f.y());
  const float y1 = lerp(lerp(t[4], t[5], f.x()), lerp(t[6], t[7], f.x()), f.y());
  return lerp(y0, y1, f.z());
}

// Normalised TSDF d/ε at p (trilinear) and whether it could be formed.
RRG_HD RRG_INLINE Sample sample_tsdf_at(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache, float& out) {
  Corners c;
  const Sample r = trilinear_corners(vol, p_w, cache, c);
  if (r == Sample::Valid) out = trilinear(c.t, c.f) * voxel_codec::kInvTsdfScale;
  return r;
}

// Normalised TSDF d/ε at p (trilinear); false where not all 8 voxels are observed.
RRG_HD RRG_INLINE bool sample_tsdf(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache, float& out) {
  return sample_tsdf_at(vol, p_w, cache, out) == Sample::Valid;
}

}  // namespace rrg::kernel
