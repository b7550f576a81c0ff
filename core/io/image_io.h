#pragma once
// Image files at the edges of core. Colour: 8-bit PNG/JPEG <-> float RGB [0,1]. Depth: 16-bit PNG
// with a scale (TUM 5000, millimetres 1000, Replica 6553.5) <-> float metres, 0 = invalid. Labels:
// 8/16-bit PNG <-> uint16. All readers throw std::runtime_error naming the file on failure; all
// writers write to a temporary file and rename, so no half-written file is ever left behind.
#include "core/common/image.h"

#include <filesystem>

namespace rrg::io {

ColorImage read_color(const std::filesystem::path& path);
void write_color_png(const std::filesystem::path& path, const ColorImage& image,
                     int png_compression = 1);

DepthImage read_depth(const std::filesystem::path& path, float depth_scale);
// Metres -> round(d * scale) as uint16; values that do not fit (or are <= 0, NaN) are written 0.
void write_depth_png(const std::filesystem::path& path, const DepthImage& depth, float depth_scale,
                     int png_compression = 1);

LabelImage read_labels(const std::filesystem::path& path);
void write_labels_png(const std::filesystem::path& path, const LabelImage& labels,
                      int png_compression = 1);
// Masks are stored as 8-bit PNG with 0 / 255.
MaskImage read_mask(const std::filesystem::path& path);
void write_mask_png(const std::filesystem::path& path, const MaskImage& mask, int png_compression = 1);

}  // namespace rrg::io
