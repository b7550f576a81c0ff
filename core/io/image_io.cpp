// Image files via OpenCV imgcodecs. Files are read into memory and decoded with cv::imdecode (so a
// missing or unreadable file gets our own message, never OpenCV's stderr noise), and written by
// encoding to a memory buffer first: the atomic writer's temporary name has no image extension.
#include "core/io/image_io.h"

#include "core/io/atomic_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw std::runtime_error("image file not found: " + path.string());
  if (fs::is_directory(path, ec)) throw std::runtime_error("image path is a folder: " + path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open image file " + path.string());
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("error reading image file " + path.string());
  return bytes;
}

// Decodes the file as stored (bit depth and channel count unchanged).
cv::Mat decode(const fs::path& path) {
  const std::vector<uint8_t> bytes = read_bytes(path);
  if (bytes.empty()) throw std::runtime_error("image file is empty: " + path.string());
  cv::Mat mat;
  try {
    mat = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot decode image file " + path.string() + ": " + e.what());
  }
  if (mat.empty()) throw std::runtime_error("cannot decode image file " + path.string() + " (not a PNG/JPEG image?)");
  return mat;
}

std::string describe(const cv::Mat& m) {
  const char* depth = m.depth() == CV_8U ? "8-bit" : m.depth() == CV_16U ? "16-bit" : "non-8/16-bit";
  return std::string(depth) + " " + std::to_string(m.channels()) + "-channel";
}

// Single-channel 8- or 16-bit check used by the depth/label/mask readers.
void require_single_channel(const cv::Mat& m, const fs::path& path, const char* what, bool allow_8bit) {
  const bool ok = m.channels() == 1 && (m.depth() == CV_16U || (allow_8bit && m.depth() == CV_8U));
  if (!ok)
    throw std::runtime_error(std::string(what) + " image " + path.string() + " is " + describe(m) + ", expected " +
                             (allow_8bit ? "8- or 16-bit" : "16-bit") + " single-channel");
}

void write_png(const fs::path& path, const cv::Mat& mat, int png_compression) {
  if (mat.empty()) throw std::invalid_argument("cannot write empty image to " + path.string());
  if (png_compression < 0 || png_compression > 9)
    throw std::invalid_argument("PNG compression must be 0..9, got " + std::to_string(png_compression));
  std::vector<uint8_t> bytes;
  const std::vector<int> params{cv::IMWRITE_PNG_COMPRESSION, png_compression};
  if (!cv::imencode(".png", mat, bytes, params)) throw std::runtime_error("PNG encoding failed for " + path.string());
  write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot create " + tmp.string());
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) throw std::runtime_error("error writing " + path.string());
  });
}

uint8_t to_u8(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return static_cast<uint8_t>(std::lround(v * 255.0f));
}

}  // namespace

ColorImage read_color(const fs::path& path) {
  const cv::Mat m = decode(path);
  const int c = m.channels();
  if (m.depth() != CV_8U && m.depth() != CV_16U)
    throw std::runtime_error("colour image " + path.string() + " is " + describe(m) + ", expected 8- or 16-bit");
  if (c != 1 && c != 3 && c != 4)
    throw std::runtime_error("colour image " + path.string() + " has " + std::to_string(c) + " channels, expected 1, 3 or 4");
  const float inv = m.depth() == CV_8U ? 1.0f / 255.0f : 1.0f / 65535.0f;
  ColorImage img(m.cols, m.rows, Color::Zero());
  for (int y = 0; y < m.rows; ++y) {
    for (int x = 0; x < m.cols; ++x) {
      auto at = [&](int ch) -> float {  // OpenCV stores B G R (A)
        return m.depth() == CV_8U ? float(m.ptr<uint8_t>(y)[x * c + ch]) : float(m.ptr<uint16_t>(y)[x * c + ch]);
      };
      if (c == 1) {
        const float g = at(0) * inv;
        img(x, y) = Color(g, g, g);
      } else {
        img(x, y) = Color(at(2) * inv, at(1) * inv, at(0) * inv);
      }
    }
  }
  return img;
}

void write_color_png(const fs::path& path, const ColorImage& image, int png_compression) {
  cv::Mat m(image.height(), image.width(), CV_8UC3);
  for (int y = 0; y < image.height(); ++y) {
    auto* row = m.ptr<uint8_t>(y);
    for (int x = 0; x < image.width(); ++x) {
      const Color& c = image(x, y);
      row[3 * x + 0] = to_u8(c.z());
      row[3 * x + 1] = to_u8(c.y());
      row[3 * x + 2] = to_u8(c.x());
    }
  }
  write_png(path, m, png_compression);
}

Image<uint16_t> read_depth_raw(const fs::path& path) {
  const cv::Mat m = decode(path);
  require_single_channel(m, path, "depth", /*allow_8bit=*/false);
  Image<uint16_t> raw(m.cols, m.rows);
  for (int y = 0; y < m.rows; ++y) std::copy_n(m.ptr<uint16_t>(y), m.cols, raw.data() + size_t(y) * m.cols);
  return raw;
}

DepthImage read_depth(const fs::path& path, float depth_scale) {
  if (!(depth_scale > 0.0f) || !std::isfinite(depth_scale))
    throw std::invalid_argument("depth scale must be > 0 (reading " + path.string() + ")");
  const Image<uint16_t> raw = read_depth_raw(path);
  DepthImage depth(raw.width(), raw.height());
  for (size_t i = 0; i < raw.size(); ++i) depth[i] = float(raw[i]) / depth_scale;
  return depth;
}

void write_depth_png(const fs::path& path, const DepthImage& depth, float depth_scale, int png_compression) {
  if (!(depth_scale > 0.0f) || !std::isfinite(depth_scale))
    throw std::invalid_argument("depth scale must be > 0 (writing " + path.string() + ")");
  cv::Mat m(depth.height(), depth.width(), CV_16UC1);
  for (int y = 0; y < depth.height(); ++y) {
    auto* row = m.ptr<uint16_t>(y);
    for (int x = 0; x < depth.width(); ++x) {
      const double v = std::round(double(depth(x, y)) * depth_scale);
      row[x] = (v > 0.0 && v <= 65535.0) ? static_cast<uint16_t>(v) : 0;  // NaN fails v > 0
    }
  }
  write_png(path, m, png_compression);
}

LabelImage read_labels(const fs::path& path) {
  const cv::Mat m = decode(path);
  require_single_channel(m, path, "label", /*allow_8bit=*/true);
  LabelImage labels(m.cols, m.rows);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      labels(x, y) = m.depth() == CV_8U ? m.ptr<uint8_t>(y)[x] : m.ptr<uint16_t>(y)[x];
  return labels;
}

void write_labels_png(const fs::path& path, const LabelImage& labels, int png_compression) {
  cv::Mat m(labels.height(), labels.width(), CV_16UC1);
  for (int y = 0; y < labels.height(); ++y) std::copy_n(&labels(0, y), labels.width(), m.ptr<uint16_t>(y));
  write_png(path, m, png_compression);
}

MaskImage read_mask(const fs::path& path) {
  const cv::Mat m = decode(path);
  require_single_channel(m, path, "mask", /*allow_8bit=*/true);
  MaskImage mask(m.cols, m.rows);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x)
      mask(x, y) = (m.depth() == CV_8U ? m.ptr<uint8_t>(y)[x] : m.ptr<uint16_t>(y)[x]) != 0 ? 1 : 0;
  return mask;
}

void write_mask_png(const fs::path& path, const MaskImage& mask, int png_compression) {
  cv::Mat m(mask.height(), mask.width(), CV_8UC1);
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) m.ptr<uint8_t>(y)[x] = mask(x, y) ? 255 : 0;
  write_png(path, m, png_compression);
}

}  // namespace rrg::io
