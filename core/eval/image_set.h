#pragma once
// Sets of rendered / captured images for `rrg eval images`. A source is a folder (its image
// files, by name) or a .txt list in the TUM style ("timestamp path" or "path" per line, '#'
// comments, paths relative to the list's folder). When every source is a folder, images are
// matched by file stem; otherwise by order. Lossless files are expected (PNG); JPEG is read but
// its compression error is then part of the score.
#include "core/common/image.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rrg::eval {

struct ImagePair {
  std::string name;  // the file stem (folders) or the estimated file's name (lists)
  std::filesystem::path est, ref;
  std::optional<std::filesystem::path> mask;  // non-zero pixels are scored
};

// The image files of a folder (sorted by name) or the entries of a .txt list. Throws
// std::runtime_error naming the path when it is missing, not a folder or .txt, has no images,
// has two files with one stem, or a list line is malformed / names a missing file.
std::vector<std::filesystem::path> list_images(const std::filesystem::path& source);

// Pairs the sources up (see above). Throws std::runtime_error naming the files found in one
// source and not the other, the counts when lists differ in length, or when nothing matched.
std::vector<ImagePair> match_images(const std::filesystem::path& est, const std::filesystem::path& ref,
                                    const std::optional<std::filesystem::path>& mask = std::nullopt);

struct ImageScore {
  ImagePair pair;
  double psnr_db = 0.0;  // +inf for identical images
  double ssim = 0.0;
};

struct ImageSetMetrics {
  std::vector<ImageScore> images;
  double mean_psnr_db = 0.0;  // mean of the per-image PSNRs (+inf if any is +inf)
  double mean_ssim = 0.0;     // mean of the per-image SSIMs
  bool masked = false;
};

// Reads every pair (core/io/image_io.h) and scores it; progress(done, total) after each image.
// Errors name the offending file(s).
ImageSetMetrics evaluate_image_pairs(const std::vector<ImagePair>& pairs,
                                     const std::function<void(size_t, size_t)>& progress = {});

}  // namespace rrg::eval
