#pragma once
// Internal to core/io: the size and layout a PNG or JPEG file declares, read from its header
// without decoding (so the frame codec can refuse a wrong-size or gigantic image before any pixel
// buffer is allocated). Bounds-checked; throws std::invalid_argument starting with `field`.
#include <cstdint>
#include <span>
#include <string_view>

namespace rrg::io {

struct ImageHeader {
  int width = 0;
  int height = 0;
  int bit_depth = 0;   // PNG: 1, 2, 4, 8, 16; JPEG: the sample precision (8 or 12)
  int color_type = 0;  // PNG colour type (0 grey, 2 RGB, 3 palette, 4 grey+alpha, 6 RGBA); JPEG: components
};

// The IHDR chunk that must follow the 8-byte PNG signature.
ImageHeader read_png_header(std::span<const uint8_t> bytes, std::string_view field);
// The first SOFn segment (baseline, extended, progressive, lossless) after SOI.
ImageHeader read_jpeg_header(std::span<const uint8_t> bytes, std::string_view field);

}  // namespace rrg::io
