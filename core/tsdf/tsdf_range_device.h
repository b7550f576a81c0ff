#pragma once
// The coarse range image of the raycast (InfiniTAM's min/max depth image): boxes where a ray can
// end on a hit are projected into a grid of kRangeTile² pixel tiles, and each tile keeps the nearest
// and farthest depth of the boxes it overlaps. A ray then marches only within its tile's
// [near, far], and a tile no box projects into is a miss without any volume lookup.
//
// The boxes: each resident block's crossing box (crossing_box_device.h), the hull of the cells
// where a march can end on a hit; a block with none (free space in front of a surface, allocated by
// fusion's band) contributes nothing. z is linear, so the depth of a ray point in a box lies between
// the depths of the box's corners, and the pixel lies inside the bounding rectangle of their
// projections.
//
// Until 2026-12-06 each block contributed its whole box [8b, 8b + 8] · s, which holds every valid
// sample, so rays began up to a block and a band before their surface (at 1280x720, 5 mm voxels,
// 2.3 block skips and 1.6 samples of free space per ray). Now a ray starts at the nearest depth of
// the boxes over its tile, about a voxel before the nearest voxel at or behind a surface there: the
// sample before the crossing is taken there instead of earlier, which changes the hit of a few
// grazing rays either way (bench/RESULTS.md, 2026-12-06).
#include "core/common/atomics.h"
#include "core/common/camera.h"
#include "core/common/fast_math.h"
#include "core/common/span.h"
#include "core/tsdf/crossing_box_device.h"
#include "core/tsdf/voxel.h"

#include <Eigen/Core>

#include <cstring>

namespace rrg::kernel {

// Pixels per tile side. 4: with boxes a few voxels deep, the tile's spread of depths (an oblique
// surface across the tile) is what a ray still marches through before its own surface.
inline constexpr int kRangeTile = 4;
inline constexpr float kNoDepth = 1e30f;   // "no box" sentinel (near of an empty tile)

// Depths are positive floats, whose bit patterns order like the floats, so the tiles keep int32
// bits and update them with atomic_max: far as +bits, near as −bits.
RRG_HD inline int32_t float_bits(float f) {
#if defined(__CUDA_ARCH__)
  return __float_as_int(f);
#else
  int32_t i;
  std::memcpy(&i, &f, sizeof i);
  return i;
#endif
}
RRG_HD inline float bits_float(int32_t i) {
#if defined(__CUDA_ARCH__)
  return __int_as_float(i);
#else
  float f;
  std::memcpy(&f, &i, sizeof f);
  return f;
#endif
}

struct RangeImage {
  Span<int32_t> near_neg;  // [tiles] −bits(nearest depth); empty: −bits(+inf)
  Span<int32_t> far;       // [tiles] bits(farthest depth); empty: bits(0)
  int tiles_x = 0, tiles_y = 0;
};

RRG_HD inline void range_clear(const RangeImage& r, int64_t tile) {
  r.near_neg[tile] = -float_bits(kNoDepth);
  r.far[tile] = 0;
}

// [near, far] of the tile holding pixel (x, y); near > far when no block projects there.
RRG_HD inline void range_at(const RangeImage& r, int x, int y, float& near, float& far) {
  const int64_t t = int64_t(y / kRangeTile) * r.tiles_x + x / kRangeTile;
  near = bits_float(-r.near_neg[t]);
  far = bits_float(r.far[t]);
}

// Projects the world box lo .. lo + size (camera R_cw, t_cw) into the tiles it may cover. The march
// samples depths z >= min_depth only, so the footprint is that of the box clipped by the plane
// z = min_depth: the bounding rectangle of the projections of the corners in front of the plane and
// of the points where the box's edges cross it (the clipped box is convex, so its image is the hull
// of its vertices' images). A box straddling the camera's plane therefore covers what it can reach,
// not the whole image: next to a wall or floor beside the camera such boxes used to pull every
// tile's near bound down to min_depth.
RRG_TU_LOCAL RRG_HD inline void range_splat_box(const RangeImage& r, const Eigen::Vector3f& lo,
                                   const Eigen::Vector3f& size, const Intrinsics& K,
                                   const Eigen::Matrix3f& R_cw, const Eigen::Vector3f& t_cw,
                                   float min_depth, float max_depth) {
  Eigen::Vector3f q[8];
  float z_lo = kNoDepth, z_hi = 0.0f;
  for (int c = 0; c < 8; ++c) {
    q[c] = R_cw * (lo + size.cwiseProduct(Eigen::Vector3f(float(c & 1), float((c >> 1) & 1), float(c >> 2)))) + t_cw;
    z_lo = min_f(z_lo, q[c].z());
    z_hi = max_f(z_hi, q[c].z());
  }
  const float z_clip = max_f(min_depth, 1e-4f);
  if (z_hi < z_clip || z_lo > max_depth) return;
  float u_lo = kNoDepth, u_hi = -kNoDepth;
  float v_lo = kNoDepth, v_hi = -kNoDepth;
  const auto add = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector2f uv = K.project(p);
    u_lo = min_f(u_lo, uv.x());
    u_hi = max_f(u_hi, uv.x());
    v_lo = min_f(v_lo, uv.y());
    v_hi = max_f(v_hi, uv.y());
  };
  for (int c = 0; c < 8; ++c) {
    if (q[c].z() >= z_clip) add(q[c]);
    for (int axis = 0; axis < 3; ++axis) {  // the 12 edges, each once from its lower corner
      const int d = c | (1 << axis);
      if (d == c) continue;
      const Eigen::Vector3f &a = q[c], &b = q[d];
      if ((a.z() < z_clip) == (b.z() < z_clip)) continue;
      const float t = (z_clip - a.z()) / (b.z() - a.z());
      Eigen::Vector3f x = a + t * (b - a);
      x.z() = z_clip;  // on the plane, whatever the rounding of the interpolation
      add(x);
    }
  }
  z_lo = max_f(z_lo, min_depth);
  // one pixel of slack for rounding
  if (u_hi < -1.0f || v_hi < -1.0f || u_lo > float(K.width) || v_lo > float(K.height)) return;
  const auto tile = [](float u, int n) {  // clamped before the conversion (u may be huge)
    return floor_to_int(min_f(max_f(u / float(kRangeTile), 0.0f), float(n - 1)));
  };
  const int tx0 = tile(u_lo - 1.0f, r.tiles_x), ty0 = tile(v_lo - 1.0f, r.tiles_y);
  const int tx1 = tile(u_hi + 1.0f, r.tiles_x), ty1 = tile(v_hi + 1.0f, r.tiles_y);
  const int32_t near_neg = -float_bits(z_lo), far = float_bits(z_hi);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) {
      const int64_t t = int64_t(ty) * r.tiles_x + tx;
      atomic_max(&r.near_neg[t], near_neg);
      atomic_max(&r.far[t], far);
    }
}

// Projects a block's crossing box (its code in TsdfVolume::crossing_boxes; nothing when it has
// none) into the tiles.
RRG_TU_LOCAL RRG_HD inline void range_splat_block(const RangeImage& r, uint32_t box, uint64_t key, float voxel_size,
                                     const Intrinsics& K, const Eigen::Matrix3f& R_cw, const Eigen::Vector3f& t_cw,
                                     float min_depth, float max_depth) {
  int lo[3], hi[3];
  if (!decode_crossing_box(box, lo, hi)) return;
  const Eigen::Vector3i g = block_coord(key) * int(kBlockSide);
  const Eigen::Vector3f corner(float(g.x() + lo[0]), float(g.y() + lo[1]), float(g.z() + lo[2]));
  const Eigen::Vector3f size(float(hi[0] + 1 - lo[0]), float(hi[1] + 1 - lo[1]), float(hi[2] + 1 - lo[2]));
  range_splat_box(r, corner * voxel_size, size * voxel_size, K, R_cw, t_cw, min_depth, max_depth);
}

}  // namespace rrg::kernel
