#pragma once
// SPZ version 3 (Niantic's compressed Gaussian splat format), written from the public format
// description: a gzip stream of a 16-byte header {magic 0x5053474e "NGSP", version 3, numPoints,
// shDegree, fractionalBits = 12, flags, reserved} then, attribute by attribute,
//   positions  24-bit signed fixed point (12 fractional bits), x y z
//   alphas     uint8 sigmoid(opacity) · 255
//   colors     uint8 f_dc · (0.15 · 255) + 127.5
//   scales     uint8 (log s + 10) · 16
//   rotations  4 bytes "smallest three": index of the largest |component| of the normalised
//              (x, y, z, w) quaternion in the top 2 bits, then per other component a sign bit and a
//              9-bit magnitude of |q_i| / sqrt(1/2)
//   sh         uint8 per coefficient (coefficient-major, colour inner), round(x · 128) + 128
//              rounded to buckets of 8 (degree 1, 5 bits) or 16 (higher degrees, 4 bits)
// Plane ids are not part of SPZ (the reflection set travels with its PLY/JSON or its own file).
// Coordinates: SPZ's own frame is RUB (three.js). rdf_to_rub converts from an OpenCV-like RDF
// frame (flips y and z of positions, the matching quaternion components and SH bands); off writes
// the frame as is (SPZ's "UNSPECIFIED").
#include "core/gaussians/gaussian_set.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace rrg {

struct SpzOptions {
  bool rdf_to_rub = false;
};

std::vector<uint8_t> encode_spz(const GaussianHost& g, const SpzOptions& options = {});
// Decodes an SPZ v2 or v3 stream (the inverse conversion when options.rdf_to_rub). Throws
// std::runtime_error on a corrupt stream, a bad magic or an unsupported version / SH degree.
GaussianHost decode_spz(const std::vector<uint8_t>& bytes, const SpzOptions& options = {});

void write_spz(const std::filesystem::path& path, const GaussianHost& g, const SpzOptions& options = {});
GaussianHost read_spz(const std::filesystem::path& path, const SpzOptions& options = {});

}  // namespace rrg
