#pragma once
// Stateless integer hashes: the only source of "randomness" in core/synth. Every random choice is
// a hash of (pixel, frame, seed) or of a quantised world position, so renders are bit-identical
// whatever the thread count and whatever order pixels are computed in.
#include <cmath>
#include <cstdint>

namespace rrg::synth {

// 32-bit avalanche hash (lowbias32 by C. Wellons).
inline uint32_t hash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}
// Order-dependent combination of several values into one hash.
inline uint32_t hash_combine(uint32_t a, uint32_t b) { return hash_u32(a ^ (hash_u32(b) + 0x9e3779b9U)); }
inline uint32_t hash3(uint32_t a, uint32_t b, uint32_t c) { return hash_combine(hash_combine(a, b), c); }
inline uint32_t hash4(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  return hash_combine(hash3(a, b, c), d);
}
// One-round hash of an integer lattice point (value noise corners): cheap, still well mixed.
inline uint32_t hash_lattice(int32_t x, int32_t y, uint32_t seed) {
  return hash_u32(uint32_t(x) * 0x8da6b343U ^ uint32_t(y) * 0xd8163841U ^ seed * 0xcb1ab31fU);
}
// Hash -> float in [0, 1) with 24 bits of resolution.
inline float unit_float(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }
// Hash -> float in [-1, 1).
inline float signed_float(uint32_t h) { return unit_float(h) * 2.0f - 1.0f; }
// Quantises a world coordinate (metres) to an integer cell of size `cell` for hashing.
inline uint32_t quantise(float x, float cell) { return uint32_t(int32_t(std::floor(x / cell))); }
// Standard normal sample from a hash (Box-Muller on two derived uniforms).
inline float gaussian_from_hash(uint32_t h) {
  const float u1 = (float(hash_u32(h) >> 8) + 0.5f) * (1.0f / 16777216.0f);
  const float u2 = unit_float(hash_u32(h ^ 0x68bc21ebU));
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(6.2831853f * u2);
}

}  // namespace rrg::synth
