#pragma once
// One voxel of the augmented TSDF (paper §3.1, supplement "TSDF Color Variance Update") and the
// packing of block coordinates into hash keys. Plain structs and RRG_HD functions: the only copy,
// shared by both back ends and by the file format (tsdf_io.cpp writes these bytes).
//
// Layout, 24 bytes per voxel, no padding (docs/tsdf.md):
//   off  0 int16  tsdf     d(p)/ε in [-1, 1], fixed point × 32767 (ε/32767 ≈ 0.6 µm at ε = 2 cm)
//   off  2 uint16 weight   W(p), number of fused observations, ≤ W_max
//   off  4 uint16 rgb[3]   c̄(p) in [0, 1] × 65535 (16 bit: a running average over W_max = 100
//                          frames still moves by steps far below one 8-bit input level)
//   off 10 uint16 n        observations on identification frames (Welford count), ≤ 65535
//   off 12 float  mu       μ, running mean of the intensity x = (r + g + b) / 3
//   off 16 float  m2       M_2, second central moment of x;  σ_c² = M_2 / n
//   off 20 uint16 r        reflection strength r(p) in [0, 1] × 65535
//   off 22 uint16 plane    plane id π(p), canonical at fusion time, 0 = none
#include "core/common/hd.h"

#include <Eigen/Core>

#include <cstdint>

namespace rrg {

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

RRG_HD inline int round_to_int(float x) { return int(x >= 0.0f ? x + 0.5f : x - 0.5f); }
RRG_HD inline int16_t encode_tsdf(float t) {  // t in [-1, 1]
  t = t < -1.0f ? -1.0f : (t > 1.0f ? 1.0f : t);
  return int16_t(round_to_int(t * kTsdfScale));
}
RRG_HD inline float decode_tsdf(int16_t q) { return float(q) / kTsdfScale; }
RRG_HD inline uint16_t encode_unit(float c) {  // c in [0, 1]
  c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
  return uint16_t(round_to_int(c * kUnitScale));
}
RRG_HD inline float decode_unit(uint16_t q) { return float(q) / kUnitScale; }
}  // namespace voxel_codec

RRG_HD inline Eigen::Vector3f voxel_color(const Voxel& v) {
  return {voxel_codec::decode_unit(v.rgb[0]), voxel_codec::decode_unit(v.rgb[1]),
          voxel_codec::decode_unit(v.rgb[2])};
}
// σ_c² = M_2 / n (0 before any identification frame).
RRG_HD inline float voxel_variance(const Voxel& v) { return v.n > 0 ? v.m2 / float(v.n) : 0.0f; }

// Block (x, y, z) holds voxels [8x, 8x + 7] × ... ; voxel g has its centre at g · s in the world.
RRG_HD inline bool block_in_range(int x, int y, int z) {
  return x >= -kKeyBias && x < kKeyBias && y >= -kKeyBias && y < kKeyBias && z >= -kKeyBias && z < kKeyBias;
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
// Floor division by 8 for negative voxel coordinates too.
RRG_HD inline int block_of(int voxel) { return voxel >> 3; }
RRG_HD inline int local_of(int voxel) { return voxel & 7; }
RRG_HD inline int local_index(int lx, int ly, int lz) { return lx + kBlockSide * (ly + kBlockSide * lz); }

}  // namespace rrg
