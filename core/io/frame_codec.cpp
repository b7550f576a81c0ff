// Frame decoding and encoding. PNG / JPEG sizes are checked from the file header (image_header.h)
// before OpenCV allocates anything, and again on the decoded image; raw forms must have exactly
// the expected byte count; RVL is strict by itself (rvl.h).
#include "core/io/frame_codec.h"

#include "core/io/image_header.h"
#include "core/io/rvl.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>

namespace rrg::io {
namespace {

static_assert(std::endian::native == std::endian::little, "raw frame forms assume a little-endian host");

std::string size_str(int64_t w, int64_t h) { return std::to_string(w) + "x" + std::to_string(h); }

[[noreturn]] void fail(std::string_view field, const std::string& what) {
  throw std::invalid_argument(std::string(field) + ": " + what);
}

void expect_bytes(std::span<const uint8_t> bytes, size_t bytes_per_pixel, int w, int h, std::string_view field,
                  const char* form) {
  const size_t need = size_t(w) * size_t(h) * bytes_per_pixel;
  if (bytes.size() != need)
    fail(field, std::string(form) + " data is " + std::to_string(bytes.size()) + " bytes, a " + size_str(w, h) +
                    " image needs " + std::to_string(need));
}

void expect_size(const ImageHeader& hdr, int w, int h, std::string_view field, const char* form) {
  if (hdr.width != w || hdr.height != h)
    fail(field, std::string(form) + " is " + size_str(hdr.width, hdr.height) + ", session expects " + size_str(w, h));
}

// cv::imdecode with our messages; `flags` as OpenCV's. The header was checked already.
cv::Mat imdecode(std::span<const uint8_t> bytes, int flags, int w, int h, std::string_view field, const char* form) {
  cv::Mat mat;
  try {
    const cv::Mat buf(1, int(bytes.size()), CV_8UC1, const_cast<uint8_t*>(bytes.data()));
    mat = cv::imdecode(buf, flags);
  } catch (const cv::Exception& e) {
    fail(field, std::string(form) + " cannot be decoded: " + e.what());
  }
  if (mat.empty()) fail(field, std::string(form) + " is corrupt (cannot be decoded)");
  if (mat.cols != w || mat.rows != h)
    fail(field, std::string(form) + " decoded to " + size_str(mat.cols, mat.rows) + ", session expects " + size_str(w, h));
  return mat;
}

std::vector<uint8_t> imencode(const char* ext, const cv::Mat& mat, const std::vector<int>& params, std::string_view field) {
  std::vector<uint8_t> out;
  bool ok = false;
  try {
    ok = cv::imencode(ext, mat, out, params);
  } catch (const cv::Exception& e) {
    fail(field, std::string("encoding ") + ext + " failed: " + e.what());
  }
  if (!ok) fail(field, std::string("encoding ") + ext + " failed");
  return out;
}

uint8_t to_u8(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN
  if (v >= 1.0f) return 255;
  return uint8_t(std::lround(v * 255.0f));
}

void check_options(const FrameEncodeOptions& o) {
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100)
    throw std::invalid_argument("encode: jpeg_quality must be 0..100, got " + std::to_string(o.jpeg_quality));
  if (o.png_compression < 0 || o.png_compression > 9)
    throw std::invalid_argument("encode: png_compression must be 0..9, got " + std::to_string(o.png_compression));
  if (o.zstd_level < 1 || o.zstd_level > 19)
    throw std::invalid_argument("encode: zstd_level must be 1..19, got " + std::to_string(o.zstd_level));
}

Image<uint16_t> to_image(std::vector<uint16_t>&& v, int w, int h) {
  Image<uint16_t> img(w, h);
  std::memcpy(img.data(), v.data(), v.size() * sizeof(uint16_t));
  return img;
}

}  // namespace

std::string to_string(ColorEncoding e) {
  switch (e) {
    case ColorEncoding::raw_rgb8: return "raw";
    case ColorEncoding::png: return "png";
    case ColorEncoding::jpeg: return "jpeg";
  }
  return "unknown";
}

std::string to_string(DepthEncoding e) {
  switch (e) {
    case DepthEncoding::raw_u16: return "raw";
    case DepthEncoding::png_u16: return "png";
    case DepthEncoding::rvl: return "rvl";
    case DepthEncoding::rvl_zstd: return "rvl+zstd";
    case DepthEncoding::raw_f32: return "raw_f32";
  }
  return "unknown";
}

ColorEncoding parse_color_encoding(std::string_view name) {
  if (name == "raw" || name == "raw_rgb8" || name == "rgb8") return ColorEncoding::raw_rgb8;
  if (name == "png") return ColorEncoding::png;
  if (name == "jpeg" || name == "jpg") return ColorEncoding::jpeg;
  throw std::invalid_argument("color: unknown encoding '" + std::string(name) + "' (raw, png, jpeg)");
}

DepthEncoding parse_depth_encoding(std::string_view name) {
  if (name == "raw" || name == "raw_u16") return DepthEncoding::raw_u16;
  if (name == "png" || name == "png_u16") return DepthEncoding::png_u16;
  if (name == "rvl") return DepthEncoding::rvl;
  if (name == "rvl+zstd" || name == "rvl_zstd") return DepthEncoding::rvl_zstd;
  if (name == "raw_f32") return DepthEncoding::raw_f32;
  throw std::invalid_argument("depth: unknown encoding '" + std::string(name) + "' (raw, png, rvl, rvl+zstd, raw_f32)");
}

// ---- decoding ----

ColorImage decode_color(std::span<const uint8_t> bytes, ColorEncoding encoding, int w, int h) {
  validate_image_size(w, h, "color");
  ColorImage out(w, h);
  if (encoding == ColorEncoding::raw_rgb8) {
    expect_bytes(bytes, 3, w, h, "color", "raw RGB8");
    constexpr float inv = 1.0f / 255.0f;  // as io::read_color, so both give identical floats
    for (size_t i = 0; i < out.size(); ++i)
      out[i] = Color(float(bytes[3 * i]) * inv, float(bytes[3 * i + 1]) * inv, float(bytes[3 * i + 2]) * inv);
    return out;
  }
  const bool png = encoding == ColorEncoding::png;
  if (!png && encoding != ColorEncoding::jpeg) fail("color", "unknown encoding " + std::to_string(int(encoding)));
  const char* form = png ? "PNG" : "JPEG";
  expect_size(png ? read_png_header(bytes, "color") : read_jpeg_header(bytes, "color"), w, h, "color", form);
  // libjpeg only warns about missing data (and fills it with grey): a JPEG must end with EOI.
  if (!png && (bytes[bytes.size() - 2] != 0xff || bytes[bytes.size() - 1] != 0xd9))
    fail("color", "JPEG truncated (does not end with the end-of-image marker)");
  // 3 channels (grey expanded, alpha dropped), 8 or 16 bits, pixels as stored (no EXIF rotation).
  const cv::Mat m = imdecode(bytes, cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH | cv::IMREAD_IGNORE_ORIENTATION, w, h,
                             "color", form);
  if (m.type() != CV_8UC3 && m.type() != CV_16UC3) fail("color", std::string(form) + " decoded to an unsupported pixel type");
  const float scale = m.depth() == CV_8U ? 1.0f / 255.0f : 1.0f / 65535.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (m.depth() == CV_8U) {
        const cv::Vec3b p = m.at<cv::Vec3b>(y, x);  // BGR
        out(x, y) = Color(float(p[2]) * scale, float(p[1]) * scale, float(p[0]) * scale);
      } else {
        const cv::Vec3w p = m.at<cv::Vec3w>(y, x);
        out(x, y) = Color(float(p[2]) * scale, float(p[1]) * scale, float(p[0]) * scale);
      }
    }
  return out;
}

Image<uint16_t> decode_u16_image(std::span<const uint8_t> bytes, DepthEncoding encoding, int w, int h,
                                 std::string_view field) {
  validate_image_size(w, h, field);
  switch (encoding) {
    case DepthEncoding::raw_u16: {
      expect_bytes(bytes, 2, w, h, field, "raw uint16");
      Image<uint16_t> out(w, h);
      std::memcpy(out.data(), bytes.data(), bytes.size());  // little-endian host
      return out;
    }
    case DepthEncoding::png_u16: {
      const ImageHeader hdr = read_png_header(bytes, field);
      expect_size(hdr, w, h, field, "PNG");
      if (hdr.bit_depth != 16 || hdr.color_type != 0)
        fail(field, "PNG is " + std::to_string(hdr.bit_depth) + "-bit colour type " + std::to_string(hdr.color_type) +
                        ", expected 16-bit greyscale");
      const cv::Mat m = imdecode(bytes, cv::IMREAD_UNCHANGED, w, h, field, "PNG");
      if (m.type() != CV_16UC1) fail(field, "PNG did not decode to 16-bit single-channel");
      Image<uint16_t> out(w, h);
      for (int y = 0; y < h; ++y) std::memcpy(&out(0, y), m.ptr<uint16_t>(y), size_t(w) * sizeof(uint16_t));
      return out;
    }
    case DepthEncoding::rvl:
    case DepthEncoding::rvl_zstd:
      try {
        return to_image(encoding == DepthEncoding::rvl ? decode_rvl(bytes, w, h) : decode_rvl_zstd(bytes, w, h), w, h);
      } catch (const std::invalid_argument& e) {
        // rvl.cpp says "depth: ..."; name the actual field.
        const std::string what = e.what();
        if (field == "depth" || what.rfind("depth: ", 0) != 0) throw;
        fail(field, what.substr(7));
      }
    case DepthEncoding::raw_f32:
      fail(field, "raw_f32 is not a 16-bit encoding");
  }
  fail(field, "unknown encoding " + std::to_string(int(encoding)));
}

DepthImage decode_depth(std::span<const uint8_t> bytes, DepthEncoding encoding, int w, int h, float depth_scale) {
  validate_depth_scale(depth_scale);
  validate_image_size(w, h, "depth");
  DepthImage out(w, h);
  if (encoding == DepthEncoding::raw_f32) {
    expect_bytes(bytes, 4, w, h, "depth", "raw float32");
    for (size_t i = 0; i < out.size(); ++i) {
      uint32_t u;
      std::memcpy(&u, bytes.data() + 4 * i, 4);
      const float d = std::bit_cast<float>(u);
      if (std::isnan(d)) fail("depth", "NaN at pixel " + std::to_string(i) + " (raw_f32 depth must be finite metres >= 0)");
      if (std::isinf(d)) fail("depth", "infinite value at pixel " + std::to_string(i) + " (raw_f32 depth must be finite metres >= 0)");
      if (d < 0.0f)
        fail("depth", "negative value " + std::to_string(d) + " at pixel " + std::to_string(i) +
                          " (raw_f32 depth must be finite metres >= 0)");
      out[i] = d;
    }
    return out;
  }
  const Image<uint16_t> raw = decode_u16_image(bytes, encoding, w, h, "depth");
  for (size_t i = 0; i < out.size(); ++i) out[i] = float(raw[i]) / depth_scale;  // as io::read_depth
  return out;
}

// ---- encoding ----

std::vector<uint8_t> encode_color(const ColorImage& color, ColorEncoding encoding, const FrameEncodeOptions& options) {
  check_options(options);
  validate_image_size(color.width(), color.height(), "color");
  if (encoding == ColorEncoding::raw_rgb8) {
    std::vector<uint8_t> out(color.size() * 3);
    for (size_t i = 0; i < color.size(); ++i)
      for (int c = 0; c < 3; ++c) out[3 * i + size_t(c)] = to_u8(color[i](c));
    return out;
  }
  cv::Mat bgr(color.height(), color.width(), CV_8UC3);
  for (int y = 0; y < color.height(); ++y)
    for (int x = 0; x < color.width(); ++x) {
      const Color& c = color(x, y);
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(to_u8(c.z()), to_u8(c.y()), to_u8(c.x()));
    }
  if (encoding == ColorEncoding::png) return imencode(".png", bgr, {cv::IMWRITE_PNG_COMPRESSION, options.png_compression}, "color");
  if (encoding == ColorEncoding::jpeg) return imencode(".jpg", bgr, {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality}, "color");
  fail("color", "unknown encoding " + std::to_string(int(encoding)));
}

std::vector<uint8_t> encode_u16_image(const Image<uint16_t>& image, DepthEncoding encoding,
                                      const FrameEncodeOptions& options) {
  check_options(options);
  const int w = image.width(), h = image.height();
  validate_image_size(w, h, "encode");
  switch (encoding) {
    case DepthEncoding::raw_u16: {
      std::vector<uint8_t> out(image.size() * 2);
      std::memcpy(out.data(), image.data(), out.size());
      return out;
    }
    case DepthEncoding::png_u16: {
      const cv::Mat m(h, w, CV_16UC1, const_cast<uint16_t*>(image.data()));
      return imencode(".png", m, {cv::IMWRITE_PNG_COMPRESSION, options.png_compression}, "encode");
    }
    case DepthEncoding::rvl: return encode_rvl(image.pixels(), w, h);
    case DepthEncoding::rvl_zstd: return encode_rvl_zstd(image.pixels(), w, h, options.zstd_level);
    case DepthEncoding::raw_f32: fail("encode", "raw_f32 is not a 16-bit encoding");
  }
  fail("encode", "unknown encoding " + std::to_string(int(encoding)));
}

std::vector<uint8_t> encode_depth(const DepthImage& depth, DepthEncoding encoding, float depth_scale,
                                  const FrameEncodeOptions& options) {
  validate_depth_scale(depth_scale);
  if (encoding == DepthEncoding::raw_f32) {
    check_options(options);
    validate_image_size(depth.width(), depth.height(), "depth");
    std::vector<uint8_t> out(depth.size() * 4);
    for (size_t i = 0; i < depth.size(); ++i) {
      const float d = std::isfinite(depth[i]) && depth[i] > 0.0f ? depth[i] : 0.0f;
      std::memcpy(out.data() + 4 * i, &d, 4);
    }
    return out;
  }
  Image<uint16_t> raw(depth.width(), depth.height());
  for (size_t i = 0; i < depth.size(); ++i) {
    const double v = std::round(double(depth[i]) * depth_scale);  // as io::write_depth_png
    raw[i] = (v >= 1.0 && v <= 65535.0) ? uint16_t(v) : 0;        // NaN compares false
  }
  return encode_u16_image(raw, encoding, options);
}

// ---- session parameters ----

void validate_image_size(int width, int height, std::string_view field) {
  if (width <= 0 || height <= 0) fail(field, "image size " + size_str(width, height) + " must be positive");
  if (int64_t(width) * height > kMaxCodecPixels)
    fail(field, "image size " + size_str(width, height) + " exceeds " + std::to_string(kMaxCodecPixels) + " pixels");
}

void validate_depth_scale(float depth_scale) {
  if (!(std::isfinite(depth_scale) && depth_scale > 0.0f))
    fail("depth", "depth_scale must be positive and finite, got " + std::to_string(depth_scale));
}

void validate_intrinsics(const Intrinsics& k) {
  validate_image_size(k.width, k.height, "intrinsics");
  // A pinhole camera's field of view 2 atan(size / (2 f)) must lie in (0.05, 170) degrees.
  constexpr double kDeg = std::numbers::pi / 180.0;
  auto check_focal = [](const char* name, float f, int size) {
    if (!(std::isfinite(f) && f > 0.0f)) fail("intrinsics", std::string(name) + " must be positive and finite, got " + std::to_string(f));
    const double fov_deg = 2.0 * std::atan(size / (2.0 * f)) / kDeg;
    if (fov_deg >= 170.0 || fov_deg <= 0.05)
      fail("intrinsics", std::string(name) + " = " + std::to_string(f) + " gives a " + std::to_string(fov_deg) +
                             " degree field of view over " + std::to_string(size) + " pixels (allowed 0.05..170)");
  };
  auto check_centre = [](const char* name, float c, int size) {
    if (!(std::isfinite(c) && c >= -0.5f && c <= float(size) - 0.5f))
      fail("intrinsics", std::string(name) + " = " + std::to_string(c) + " is outside the image [-0.5, " +
                             std::to_string(size) + " - 0.5]");
  };
  check_focal("fx", k.fx, k.width);
  check_focal("fy", k.fy, k.height);
  check_centre("cx", k.cx, k.width);
  check_centre("cy", k.cy, k.height);
}

}  // namespace rrg::io
