#pragma once
// RVL lossless depth compression (Andrew D. Wilson, "Fast Lossless Depth Image Compression", ISS
// 2017), written from the paper's description, plus an optional zstd layer on top (rvl+zstd).
//
// RVL stream: the pixels in row-major order as alternating runs, [number of zeros][number of
// non-zeros][value_1]...[value_k], repeated until every pixel is covered. Each non-zero value is
// stored as the zigzag-folded delta to the previous non-zero value (start 0): e = (d << 1) ^ (d >> 31).
// Every integer is a variable-length code of 3-bit groups, least significant first, each in a nibble
// whose high bit says "more follows". Nibbles fill 32-bit words from the most significant nibble
// down; words are stored little-endian; the last word is zero-padded. No header: the receiver knows
// the image size (the session's), so the byte count is always a multiple of 4 (0 for 0 pixels).
//
// Decoding is strict: anything an encoder cannot have produced (a truncated stream, a run past the
// last pixel, a value outside 1..65535, a run that is not maximal, a code with superfluous nibbles,
// trailing words or non-zero padding) throws std::invalid_argument naming the pixel; it never reads
// out of bounds. So every accepted stream is canonical: encode_rvl(decode_rvl(s)) == s (fuzzed).
#include <cstdint>
#include <span>
#include <vector>

namespace rrg::io {

// The largest image the codecs accept (pixels): 16384 x 16384. Bounds what a stream can allocate.
inline constexpr int64_t kMaxCodecPixels = int64_t(1) << 28;

// depth.size() must be width * height (row-major uint16 depth, 0 = invalid).
std::vector<uint8_t> encode_rvl(std::span<const uint16_t> depth, int width, int height);
std::vector<uint16_t> decode_rvl(std::span<const uint8_t> bytes, int width, int height);

// rvl+zstd: one zstd frame (content size and checksum stored) whose content is the RVL stream above. zstd_level
// 1..19 (default 1: fast; sizes in docs/codecs.md).
std::vector<uint8_t> encode_rvl_zstd(std::span<const uint16_t> depth, int width, int height, int zstd_level = 1);
std::vector<uint16_t> decode_rvl_zstd(std::span<const uint8_t> bytes, int width, int height);

// An upper bound on an RVL stream's size for `pixels` pixels (what decode_rvl_zstd lets zstd
// produce at most; guards against decompression bombs).
int64_t rvl_max_bytes(int64_t pixels);

}  // namespace rrg::io
