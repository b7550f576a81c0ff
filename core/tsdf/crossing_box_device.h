#pragma once
// A block's crossing box: where in its region a ray march can end on a hit (tsdf_range_device.h).
// A march ends at a valid sample with f ≤ 0; the trilinear value is a convex combination of the
// cell's 8 corners, so that cell has an observed corner v with d(v) ≤ 0 and the sample lies in
// [v − 1, v + 1] · s. A block's crossing box is the hull of those boxes over its observed voxels
// with d ≤ 0. The volume keeps one code per resident block (TsdfVolume::crossing_boxes), refreshed
// where voxels change (fusion's active blocks, blocks written back by streaming and loading), so a
// raycast reads it instead of scanning 512 voxels per block.
#include "core/common/fast_math.h"
#include "core/common/span.h"
#include "core/tsdf/voxel.h"

#include <cstdint>

namespace rrg::kernel {

// Codes: kBoxUnknown (never computed: the box of every voxel, offsets −1 .. 8), kNoCrossing (no
// observed voxel with d ≤ 0), or kBoxKnown | per axis k (lo + 1) << 8k | (hi + 1) << (8k + 4).
inline constexpr uint32_t kBoxUnknown = 0u;
inline constexpr uint32_t kNoCrossing = 1u;
inline constexpr uint32_t kBoxKnown = 1u << 31;

// The crossing box of block b (pool index; its voxels start at b · 512) as voxel offsets lo .. hi + 1
// from the block's voxel 0 (lo in −1 .. 7, hi + 1 in 1 .. 9); false when it has no observed voxel
// with d ≤ 0. One pass over the block's 512 TSDF values, a row of 8 as a bit mask.
RRG_HD RRG_INLINE bool crossing_box(Span<const TsdfVoxel> geometry, int64_t b, int lo[3], int hi[3]) {
  const TsdfVoxel* v = &geometry[b * kBlockVoxels];
  int x_lo = kBlockSide, x_hi = -1, y_lo = kBlockSide, y_hi = -1, z_lo = kBlockSide, z_hi = -1;
  for (int z = 0; z < kBlockSide; ++z)
    for (int y = 0; y < kBlockSide; ++y) {
      const TsdfVoxel* row = v + local_index(0, y, z);
      uint32_t mask = 0;
      RRG_UNROLL
      for (int x = 0; x < kBlockSide; ++x) mask |= uint32_t(row[x].weight != 0 && row[x].tsdf <= 0) << x;
      if (mask == 0) continue;
      const int a = lowest_bit(mask), c = highest_bit(mask);
      x_lo = a < x_lo ? a : x_lo;
      x_hi = c > x_hi ? c : x_hi;
      y_lo = y < y_lo ? y : y_lo;
      y_hi = y > y_hi ? y : y_hi;
      z_lo = z < z_lo ? z : z_lo;
      z_hi = z;
    }
  lo[0] = x_lo - 1, lo[1] = y_lo - 1, lo[2] = z_lo - 1;
  hi[0] = x_hi, hi[1] = y_hi, hi[2] = z_hi;
  return x_hi >= 0;
}

RRG_HD RRG_INLINE uint32_t encode_crossing_box(Span<const TsdfVoxel> geometry, int64_t b) {
  int lo[3], hi[3];
  if (!crossing_box(geometry, b, lo, hi)) return kNoCrossing;
  uint32_t code = kBoxKnown;
  for (int k = 0; k < 3; ++k) code |= (uint32_t(lo[k] + 1) << (8 * k)) | (uint32_t(hi[k] + 1) << (8 * k + 4));
  return code;
}

// The box of a code as crossing_box gives it; false for kNoCrossing.
RRG_HD RRG_INLINE bool decode_crossing_box(uint32_t code, int lo[3], int hi[3]) {
  if (code == kNoCrossing) return false;
  for (int k = 0; k < 3; ++k) {
    lo[k] = code == kBoxUnknown ? -1 : int((code >> (8 * k)) & 15u) - 1;
    hi[k] = code == kBoxUnknown ? kBlockSide - 1 : int((code >> (8 * k + 4)) & 15u) - 1;
  }
  return true;
}

}  // namespace rrg::kernel
