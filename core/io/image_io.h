#pragma once
// Image files at the edges of core. Colour: 8-bit PNG/JPEG <-> float RGB [0,1]. Depth: 16-bit PNG
// with a scale (TUM 5000, millimetres 1000, Replica 6553.5) <-> float metres, 0 = invalid. Labels:
// 8/16-bit PNG <-> uint16. All readers throw std::runtime_error naming the file on failure; all
// writers write to a temporary file and rename, so no half-written file is ever left behind.
#include "core/common/image.h"

#include <filesystem>

namespace rrg::io {

// 8- or 16-bit, 1 (grey), 3 or 4 (alpha dropped) channels -> float RGB [0,1].
ColorImage read_color(const std::filesystem::path& path);
// Float RGB [0,1] -> 8-bit RGB PNG, round(c * 255) clamped.
void write_color_png(const std::filesystem::path& path, const ColorImage& image,
                     int png_compression = 1);

// 16-bit single-channel PNG (anything else is an error) -> stored / depth_scale metres.
DepthImage read_depth(const std::filesystem::path& path, float depth_scale);
// The stored 16-bit values, unscaled (for readers with special codes, e.g. 7-Scenes' 65535).
Image<uint16_t> read_depth_raw(const std::filesystem::path& path);
// Metres -> round(d * scale) as uint16; values that do not fit (or are <= 0, NaN) are written 0.
void write_depth_png(const std::filesystem::path& path, const DepthImage& depth, float depth_scale,
                     int png_compression = 1);

// Single-channel 8- or 16-bit PNG; written as 16-bit.
LabelImage read_labels(const std::filesystem::path& path);
void write_labels_png(const std::filesystem::path& path, const LabelImage& labels,
                      int png_compression = 1);
// Masks are stored as 8-bit PNG with 0 / 255; any non-zero stored value reads as 1.
MaskImage read_mask(const std::filesystem::path& path);
void write_mask_png(const std::filesystem::path& path, const MaskImage& mask, int png_compression = 1);

}  // namespace rrg::io
