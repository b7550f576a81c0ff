#pragma once
// Encoded RGB-D frames as they travel between a client and the reconstruction service: colour as
// JPEG / PNG / raw RGB8, depth as RVL / RVL+zstd / 16-bit PNG / raw uint16 / raw float32, labels as
// any of the lossless 16-bit forms. Decoders check everything against the size the session expects
// and throw std::invalid_argument whose message starts with the field ("color: ", "depth: ",
// "labels: ", "intrinsics: ") and says what is wrong, e.g.
//   "color: JPEG is 640x480, session expects 320x240"
//   "depth: RVL stream truncated at pixel 1234 of 76800"
//   "depth: NaN at pixel 17 (raw_f32 depth must be finite metres >= 0)"
// They never crash or over-read on corrupt input (fuzzed: tests/fuzz). Formats: docs/codecs.md.
#include "core/common/camera.h"
#include "core/common/image.h"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rrg::io {

enum class ColorEncoding {
  raw_rgb8,  // width * height * 3 bytes, row-major, R G B
  png,       // 8- or 16-bit, grey / RGB / RGBA PNG (alpha dropped)
  jpeg,      // baseline or progressive JPEG (EXIF orientation ignored: pixels as stored)
};

enum class DepthEncoding {
  raw_u16,   // width * height * 2 bytes, little-endian uint16, metres = value / depth_scale
  png_u16,   // 16-bit single-channel PNG, metres = value / depth_scale
  rvl,       // core/io/rvl.h, metres = value / depth_scale
  rvl_zstd,  // core/io/rvl.h, metres = value / depth_scale
  raw_f32,   // width * height * 4 bytes, little-endian float32 metres (depth_scale unused);
             // 0 = invalid; NaN, infinite or negative values are rejected
};

// Names used on the command line and in logs: "raw" / "png" / "jpeg" and "raw" (= raw_u16) /
// "png" / "rvl" / "rvl+zstd" / "raw_f32". Parsing throws std::invalid_argument listing the names.
std::string to_string(ColorEncoding e);
std::string to_string(DepthEncoding e);
ColorEncoding parse_color_encoding(std::string_view name);
DepthEncoding parse_depth_encoding(std::string_view name);

// A protobuf `bytes` field (std::string) or any char buffer as the decoders' input.
inline std::span<const uint8_t> byte_span(std::string_view s) {
  return {reinterpret_cast<const uint8_t*>(s.data()), s.size()};
}

// ---- decoding (server side) ----

// -> float RGB in [0,1] (8-bit / 255, 16-bit / 65535), exactly width x height.
ColorImage decode_color(std::span<const uint8_t> bytes, ColorEncoding encoding, int width, int height);
// -> metres, 0 = invalid, exactly width x height. depth_scale: stored units per metre (> 0, finite).
DepthImage decode_depth(std::span<const uint8_t> bytes, DepthEncoding encoding, int width, int height,
                        float depth_scale);
// The stored 16-bit values of a lossless 16-bit encoding (raw_u16, png_u16, rvl, rvl_zstd), e.g. a
// label image; `field` names it in error messages.
Image<uint16_t> decode_u16_image(std::span<const uint8_t> bytes, DepthEncoding encoding, int width, int height,
                                 std::string_view field = "labels");

// ---- encoding (client side) ----

struct FrameEncodeOptions {
  int jpeg_quality = 90;    // 0..100
  int png_compression = 1;  // 0..9 (1: fast, the stream's choice)
  int zstd_level = 1;       // 1..19, rvl_zstd only
};

// Colour c in [0,1] -> round(c * 255) clamped, 8 bits per channel.
std::vector<uint8_t> encode_color(const ColorImage& color, ColorEncoding encoding,
                                  const FrameEncodeOptions& options = {});
// Metres -> round(d * depth_scale) as uint16 (values <= 0, NaN or too large for uint16 become 0);
// raw_f32 stores metres as they are (NaN, infinite or negative become 0).
std::vector<uint8_t> encode_depth(const DepthImage& depth, DepthEncoding encoding, float depth_scale,
                                  const FrameEncodeOptions& options = {});
// 16-bit values as they are (raw_f32 is refused).
std::vector<uint8_t> encode_u16_image(const Image<uint16_t>& image, DepthEncoding encoding,
                                      const FrameEncodeOptions& options = {});

// ---- session parameters ----

// Width and height positive, at most 2^28 pixels in all (kMaxCodecPixels in core/io/rvl.h).
void validate_image_size(int width, int height, std::string_view field);
// depth_scale finite and > 0 ("depth: depth_scale must be positive and finite, got -1").
void validate_depth_scale(float depth_scale);
// fx, fy finite and positive, a field of view below 170 degrees and above 0.05 degrees on both
// axes, principal point inside the image ([-0.5, size - 0.5]), valid width and height:
// "intrinsics: fx must be positive, got 0".
void validate_intrinsics(const Intrinsics& intrinsics);

}  // namespace rrg::io
