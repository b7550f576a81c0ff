#pragma once
// Reading the volume at world points: voxel lookup through the hash (with a one-block cache) and
// trilinear interpolation over the 8 voxels around a point. Shared by raycasting and tests.
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

// The last few blocks looked up, so that a ray's samples (and the ± offsets of a normal's central
// differences, which straddle block borders) probe the hash table once per block, not per sample.
struct BlockCache {
  static constexpr int kEntries = 4;  // a power of two
  uint64_t key[kEntries] = {kEmptyKey, kEmptyKey, kEmptyKey, kEmptyKey};
  int32_t block[kEntries] = {-1, -1, -1, -1};
  int next = 0;
};

// Pool index of the block with coordinates (bx, by, bz), or -1 when it is not resident.
RRG_HD RRG_INLINE int32_t cached_block(const VolumeView& vol, int bx, int by, int bz, BlockCache& cache) {
  if (!block_in_range(bx, by, bz)) return -1;
  const uint64_t key = block_key(bx, by, bz);
  RRG_UNROLL
  for (int e = 0; e < BlockCache::kEntries; ++e)
    if (cache.key[e] == key) return cache.block[e];
  const int32_t b = hash_find(vol.hash, key);
  cache.key[cache.next] = key;
  cache.block[cache.next] = b;
  cache.next = (cache.next + 1) & (BlockCache::kEntries - 1);
  return b;
}

// Trilinear sampling at p: the cell of p is the voxels g .. g + 1 with g = floor(p / s) (its lower
// corner), p = (g + f) · s with f in [0, 1)³.
enum class Sample {
  NoBlock,     // the block of the lower corner g is not resident: nothing valid nearby
  Unobserved,  // a corner is in a missing block or has weight 0
  Valid,
};

// The TSDF values of the 8 voxels around p (corner c = dx + 2 dy + 4 dz) in fixed-point units
// (d/ε × voxel_codec::kTsdfScale: scaled once after interpolating) and p's position f in the cell.
struct Corners {
  float t[8];
  Eigen::Vector3f f;
};

RRG_HD RRG_INLINE Sample trilinear_corners(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache,
                                       Corners& out) {
  const Eigen::Vector3f q = p_w * (1.0f / vol.voxel_size);
  const int gx = floor_to_int(q.x()), gy = floor_to_int(q.y()), gz = floor_to_int(q.z());
  out.f = Eigen::Vector3f(q.x() - float(gx), q.y() - float(gy), q.z() - float(gz));
  const int lx = local_of(gx), ly = local_of(gy), lz = local_of(gz);
  const int bx = block_of(gx), by = block_of(gy), bz = block_of(gz);
  const int32_t b0 = cached_block(vol, bx, by, bz, cache);
  if (b0 < 0) return Sample::NoBlock;
  const int64_t v0 = int64_t(b0) * kBlockVoxels + local_index(lx, ly, lz);
  int unobserved = 0;
  if (lx < kBlockSide - 1 && ly < kBlockSide - 1 && lz < kBlockSide - 1) {
    // The whole cell in one block (7/8 of the cells per axis): fixed offsets from the lower corner.
    RRG_UNROLL
    for (int c = 0; c < 8; ++c) {
      const int64_t v = v0 + local_index(c & 1, (c >> 1) & 1, c >> 2);
      const TsdfVoxel g = vol.geometry[v];
      unobserved |= int(g.weight == 0);
      out.t[c] = float(g.tsdf);
    }
    return unobserved ? Sample::Unobserved : Sample::Valid;
  }
  // The cell straddles blocks: where a local coordinate is 7, the corners one further lie in the
  // +x / +y / +z neighbour; each of those blocks is looked up once, through the cache.
  const bool ox = lx == kBlockSide - 1, oy = ly == kBlockSide - 1, oz = lz == kBlockSide - 1;
  const int crossing = int(ox) | (int(oy) << 1) | (int(oz) << 2);
  int64_t first[8] = {int64_t(b0) * kBlockVoxels};  // voxel 0 of each block (bit 0: +x, 1: +y, 2: +z)
  for (int o = 1; o < 8; ++o) {
    if (o & ~crossing) continue;  // no corner in that neighbour
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
    unobserved |= int(g.weight == 0);
    out.t[c] = float(g.tsdf);
  }
  return unobserved ? Sample::Unobserved : Sample::Valid;
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
