#pragma once
// Reading the volume at world points: voxel lookup through the hash (with a one-block cache) and
// trilinear interpolation over the 8 voxels around a point. Shared by raycasting and tests.
#include "core/tsdf/voxel_hash_device.h"

#include <Eigen/Core>

#include <cmath>

namespace rrg::kernel {

struct VolumeView {
  HashView hash;
  Span<const Voxel> voxels;  // [blocks * 512]
  float voxel_size;
};

struct BlockCache {  // the last block looked up
  uint64_t key = kEmptyKey;
  int32_t block = -1;
};

// Voxel with global coordinates g (centre at g · s), or nullptr when its block is not resident.
RRG_HD inline const Voxel* voxel_at(const VolumeView& vol, const Eigen::Vector3i& g, BlockCache& cache) {
  const int bx = block_of(g.x()), by = block_of(g.y()), bz = block_of(g.z());
  if (!block_in_range(bx, by, bz)) return nullptr;
  const uint64_t key = block_key(bx, by, bz);
  if (key != cache.key) {
    cache.key = key;
    cache.block = hash_find(vol.hash, key);
  }
  if (cache.block < 0) return nullptr;
  return &vol.voxels[int64_t(cache.block) * kBlockVoxels + local_index(local_of(g.x()), local_of(g.y()), local_of(g.z()))];
}

// The 8 voxels around p and their trilinear weights w_i; false when one is missing or unobserved.
struct Corners {
  const Voxel* v[8];
  float w[8];
};
RRG_HD inline bool trilinear_corners(const VolumeView& vol, const Eigen::Vector3f& p_w, BlockCache& cache,
                                     Corners& out) {
  const Eigen::Vector3f q = p_w / vol.voxel_size;
  const Eigen::Vector3f b(floorf(q.x()), floorf(q.y()), floorf(q.z()));
  const Eigen::Vector3f f = q - b;
  const Eigen::Vector3i base(int(b.x()), int(b.y()), int(b.z()));
  const int lx = local_of(base.x()), ly = local_of(base.y()), lz = local_of(base.z());
  const Voxel* inner = nullptr;  // all 8 corners in one block: one lookup, direct indexing
  if (lx < kBlockSide - 1 && ly < kBlockSide - 1 && lz < kBlockSide - 1) {
    inner = voxel_at(vol, base, cache);
    if (!inner) return false;
  }
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    const Voxel* v = inner ? inner + (dx + kBlockSide * (dy + kBlockSide * dz))
                           : voxel_at(vol, base + Eigen::Vector3i(dx, dy, dz), cache);
    if (!v || v->weight == 0) return false;
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
  for (int i = 0; i < 8; ++i) f += c.w[i] * voxel_codec::decode_tsdf(c.v[i]->tsdf);
  out = f;
  return true;
}

}  // namespace rrg::kernel
