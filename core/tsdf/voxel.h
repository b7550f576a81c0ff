#pragma once
// One voxel of the augmented TSDF (paper §3.1, supplement "TSDF Color Variance Update") and the
// packing of block coordinates into hash keys. Plain structs and RRG_HD functions: the only copy,
// shared by both back ends and by the file format (tsdf_io.cpp writes Voxel records).
//
// On the device a voxel lives in two layers, each an array of 512 per block (DESIGN.md §3; the
// split of Open3D's VoxelBlockGrid attributes and nvblox's layers): ray marching, normals and
// marching cubes read only the 4-byte geometry layer, so a block's geometry is 2 KB (32 cache
// lines) instead of the 12 KB of whole voxels; colour and reflection attributes are read once per
// hit. The record `Voxel` (both layers, 24 bytes) is what files, host copies and tests see.
//
// Voxel record, 24 bytes, no padding (docs/tsdf.md):
//   off  0 int16  tsdf     d(p)/ε in [-1, 1], fixed point × 32767 (ε/32767 ≈ 0.6 µm at ε = 2 cm)
//   off  2 uint16 weight   W(p), number of fused observations, ≤ W_max
//   off  4 uint16 rgb[3]   c̄(p) in [0, 1] × 65535 (16 bit: a running average over W_max = 100
//                          frames still moves by steps far below one 8-bit input level)
//   off 10 uint16 n        observations on identification frames (Welford count), ≤ 65535
//   off 12 float  mu       μ, running mean of the intensity x = (r + g + b) / 3
//   off 16 float  m2       M_2, second central moment of x;  σ_c² = M_2 / n
//   off 20 uint16 r        reflection strength r(p) in [0, 1] × 65535
//   off 22 uint16 plane    plane id π(p), canonical at fusion time, 0 = none
#include "core/common/fast_math.h"
#include "core/common/hd.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace rrg {

// Geometry layer: bytes 0-3 of the record.
struct TsdfVoxel {
  int16_t tsdf = 0;
  uint16_t weight = 0;
};
static_assert(sizeof(TsdfVoxel) == 4);

// Attribute layer: bytes 4-23 of the record.
struct AttrVoxel {
  uint16_t rgb[3] = {0, 0, 0};
  uint16_t n = 0;
  float mu = 0.0f;
  float m2 = 0.0f;
  uint16_t r = 0;
  uint16_t plane = 0;
};
static_assert(sizeof(AttrVoxel) == 20);

struct Voxel {
  int16_t tsdf = 0;
  uint16_t weight = 0;
  uint16_t rgb[3] = {0, 0, 0};
  uint16_t n = 0;
  float mu = 0.0f;
  float m2 = 0.0f;
  uint16_t r = 0;
  uint16_t plane = 0;
};
static_assert(sizeof(Voxel) == 24, "Voxel layout is part of the file format");

RRG_HD inline Voxel join_voxel(const TsdfVoxel& g, const AttrVoxel& a) {
  Voxel v;
  v.tsdf = g.tsdf;
  v.weight = g.weight;
  for (int k = 0; k < 3; ++k) v.rgb[k] = a.rgb[k];
  v.n = a.n;
  v.mu = a.mu;
  v.m2 = a.m2;
  v.r = a.r;
  v.plane = a.plane;
  return v;
}
RRG_HD inline TsdfVoxel voxel_geometry(const Voxel& v) { return {v.tsdf, v.weight}; }
RRG_HD inline AttrVoxel voxel_attributes(const Voxel& v) {
  AttrVoxel a;
  for (int k = 0; k < 3; ++k) a.rgb[k] = v.rgb[k];
  a.n = v.n;
  a.mu = v.mu;
  a.m2 = v.m2;
  a.r = v.r;
  a.plane = v.plane;
  return a;
}

struct Rgb8 {  // 8-bit colour input (as stored in PNG/JPEG)
  uint8_t r = 0, g = 0, b = 0;
};

inline constexpr int kBlockSide = 8;                 // voxels per block edge
inline constexpr int kBlockVoxels = 512;             // 8³
inline constexpr uint64_t kEmptyKey = ~uint64_t{0};  // unused hash slot (never a valid key)
inline constexpr int kKeyBits = 21;                  // per axis: block coordinates in [-2^20, 2^20)
inline constexpr int kKeyBias = 1 << 20;

namespace voxel_codec {
inline constexpr float kTsdfScale = 32767.0f;
inline constexpr float kUnitScale = 65535.0f;

inline constexpr float kInvTsdfScale = 1.0f / kTsdfScale;
inline constexpr float kInvUnitScale = 1.0f / kUnitScale;

// Branch-free on both back ends (fusion runs these for every voxel; a sign branch there is a
// misprediction at every surface): clamp, then round half away from zero.
RRG_HD inline int16_t encode_tsdf(float t) {  // t in [-1, 1]
  t = min_f(max_f(t, -1.0f), 1.0f) * kTsdfScale;  // NaN → −1, as fminf(fmaxf(NaN, −1), 1)
  return int16_t(int(t + copysignf(0.5f, t)));
}
RRG_HD inline float decode_tsdf(int16_t q) { return float(q) * kInvTsdfScale; }
RRG_HD inline uint16_t encode_unit(float c) {  // c in [0, 1]
  return uint16_t(int(min_f(max_f(c, 0.0f), 1.0f) * kUnitScale + 0.5f));
}
RRG_HD inline float decode_unit(uint16_t q) { return float(q) * kInvUnitScale; }
}  // namespace voxel_codec

template <class V>  // Voxel or AttrVoxel
RRG_HD inline Eigen::Vector3f voxel_color(const V& v) {
  return {voxel_codec::decode_unit(v.rgb[0]), voxel_codec::decode_unit(v.rgb[1]),
          voxel_codec::decode_unit(v.rgb[2])};
}
// σ_c² = M_2 / n (0 before any identification frame).
template <class V>
RRG_HD inline float voxel_variance(const V& v) { return v.n > 0 ? v.m2 / float(v.n) : 0.0f; }
// The intensity x = (r + g + b) / 3 whose Welford statistics (μ, M_2, n) a voxel keeps.
RRG_HD inline float welford_intensity(const Eigen::Vector3f& c) { return (c.x() + c.y() + c.z()) * (1.0f / 3.0f); }

// Block (x, y, z) holds voxels [8x, 8x + 7] × ... ; voxel g has its centre at g · s in the world.
RRG_HD inline bool block_in_range(int x, int y, int z) {
  // x in [−2^20, 2^20) ⟺ x + 2^20 in [0, 2^21), as an unsigned number (negative ones wrap high).
  constexpr uint32_t bias = kKeyBias;
  return (((uint32_t(x) + bias) | (uint32_t(y) + bias) | (uint32_t(z) + bias)) >> kKeyBits) == 0;
}
RRG_HD inline uint64_t block_key(int x, int y, int z) {
  return (uint64_t(x + kKeyBias) << (2 * kKeyBits)) | (uint64_t(y + kKeyBias) << kKeyBits) |
         uint64_t(z + kKeyBias);
}
RRG_HD inline Eigen::Vector3i block_coord(uint64_t key) {
  constexpr uint64_t m = (uint64_t{1} << kKeyBits) - 1;
  return {int((key >> (2 * kKeyBits)) & m) - kKeyBias, int((key >> kKeyBits) & m) - kKeyBias,
          int(key & m) - kKeyBias};
}
// The centre of block c's voxel centres (voxels 8c .. 8c + 7 on each axis), world metres.
RRG_HD inline Eigen::Vector3f block_center(const Eigen::Vector3i& c, float voxel_size) {
  return (c.cast<float>() * float(kBlockSide) + Eigen::Vector3f::Constant(3.5f)) * voxel_size;
}
// Floor division by 8 for negative voxel coordinates too.
RRG_HD inline int block_of(int voxel) { return voxel >> 3; }
RRG_HD inline int local_of(int voxel) { return voxel & 7; }
RRG_HD inline int local_index(int lx, int ly, int lz) { return lx + kBlockSide * (ly + kBlockSide * lz); }

}  // namespace rrg
