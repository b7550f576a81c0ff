// RVL (Wilson 2017) and the rvl+zstd layer. The nibble writer/reader follow the paper: 3 data bits
// and a continuation bit per nibble, eight nibbles per 32-bit word, most significant nibble first.
#include "core/io/rvl.h"

#include <zstd.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace rrg::io {
namespace {

// Longest variable-length code we accept: 11 nibbles = 33 bits, enough for any run length of an
// image of kMaxCodecPixels and for every zigzag delta (17 bits).
constexpr int kMaxCodeNibbles = 11;

void check_size(int width, int height, const char* what) {
  if (width < 0 || height < 0)
    throw std::invalid_argument(std::string("depth: ") + what + ": negative size " + std::to_string(width) + "x" +
                                std::to_string(height));
  if (int64_t(width) * int64_t(height) > kMaxCodecPixels)
    throw std::invalid_argument(std::string("depth: ") + what + ": " + std::to_string(width) + "x" +
                                std::to_string(height) + " exceeds the codec limit of " +
                                std::to_string(kMaxCodecPixels) + " pixels");
}

class NibbleWriter {
 public:
  explicit NibbleWriter(std::vector<uint8_t>& out) : out_(out) {}
  // Variable-length code: 3 bits per nibble, low bits first, bit 3 = more to come.
  void put(uint32_t value) {
    do {
      uint32_t nibble = value & 0x7u;
      value >>= 3;
      if (value) nibble |= 0x8u;
      word_ = (word_ << 4) | nibble;
      if (++nibbles_ == 8) flush();
    } while (value);
  }
  void finish() {
    if (nibbles_ == 0) return;
    word_ <<= 4 * (8 - nibbles_);  // zero padding in the low nibbles
    flush();
  }

 private:
  void flush() {
    for (int b = 0; b < 4; ++b) out_.push_back(uint8_t(word_ >> (8 * b)));  // little-endian word
    word_ = 0;
    nibbles_ = 0;
  }
  std::vector<uint8_t>& out_;
  uint32_t word_ = 0;
  int nibbles_ = 0;
};

class NibbleReader {
 public:
  NibbleReader(std::span<const uint8_t> bytes, int64_t pixels) : bytes_(bytes), pixels_(pixels) {}

  // One code; `pixel` (how many pixels are decoded so far) only feeds the error messages.
  uint64_t get(int64_t pixel) {
    uint64_t value = 0;
    for (int i = 0; i < kMaxCodeNibbles; ++i) {
      const uint32_t nibble = next(pixel);
      value |= uint64_t(nibble & 0x7u) << (3 * i);
      if (nibble & 0x8u) continue;
      if (i > 0 && nibble == 0)  // the encoder stops before a final all-zero group
        throw std::invalid_argument("depth: RVL code with a superfluous zero nibble at pixel " + std::to_string(pixel) +
                                    where());
      return value;
    }
    throw std::invalid_argument("depth: RVL code longer than " + std::to_string(kMaxCodeNibbles) +
                                " nibbles at pixel " + std::to_string(pixel) + where());
  }

  // After the last pixel: the rest of the current word must be zero padding and no word may follow.
  void expect_end(int64_t pixel) const {
    if (nibbles_left_ > 0 && (word_ >> (32 - 4 * nibbles_left_)) != 0)
      throw std::invalid_argument("depth: RVL stream has non-zero padding after pixel " + std::to_string(pixel));
    if (pos_ != bytes_.size())
      throw std::invalid_argument("depth: RVL stream has " + std::to_string(bytes_.size() - pos_) +
                                  " trailing bytes after the last pixel");
  }

  std::string where() const { return " of " + std::to_string(pixels_) + " (byte " + std::to_string(pos_) + ")"; }

 private:
  uint32_t next(int64_t pixel) {
    if (nibbles_left_ == 0) {
      if (bytes_.size() - pos_ < 4)
        throw std::invalid_argument("depth: RVL stream truncated at pixel " + std::to_string(pixel) + " of " +
                                    std::to_string(pixels_) + " (" + std::to_string(bytes_.size()) + " bytes)");
      word_ = uint32_t(bytes_[pos_]) | uint32_t(bytes_[pos_ + 1]) << 8 | uint32_t(bytes_[pos_ + 2]) << 16 |
              uint32_t(bytes_[pos_ + 3]) << 24;
      pos_ += 4;
      nibbles_left_ = 8;
    }
    const uint32_t nibble = word_ >> 28;
    word_ <<= 4;
    --nibbles_left_;
    return nibble;
  }

  std::span<const uint8_t> bytes_;
  int64_t pixels_;
  size_t pos_ = 0;
  uint32_t word_ = 0;
  int nibbles_left_ = 0;
};

}  // namespace

int64_t rvl_max_bytes(int64_t pixels) {
  // Worst case per pixel: a 1-pixel zero run and a 1-pixel non-zero run (1 + 1 nibbles) plus a
  // 17-bit delta (6 nibbles): 8 nibbles = 4 bytes per pixel; plus two long run codes and padding.
  return 4 * pixels + 2 * kMaxCodeNibbles + 8;
}

std::vector<uint8_t> encode_rvl(std::span<const uint16_t> depth, int width, int height) {
  check_size(width, height, "RVL encode");
  const size_t n = size_t(width) * size_t(height);
  if (depth.size() != n)
    throw std::invalid_argument("depth: RVL encode: " + std::to_string(depth.size()) + " values for a " +
                                std::to_string(width) + "x" + std::to_string(height) + " image");
  std::vector<uint8_t> out;
  out.reserve(n);  // typical Kinect depth compresses to ~1 byte per pixel or less
  NibbleWriter w(out);
  int32_t previous = 0;
  size_t i = 0;
  while (i < n) {
    size_t zeros = 0, nonzeros = 0;
    while (i + zeros < n && depth[i + zeros] == 0) ++zeros;
    i += zeros;
    while (i + nonzeros < n && depth[i + nonzeros] != 0) ++nonzeros;
    w.put(uint32_t(zeros));
    w.put(uint32_t(nonzeros));
    for (size_t k = 0; k < nonzeros; ++k, ++i) {
      const int32_t current = depth[i];
      const int32_t delta = current - previous;
      w.put(uint32_t(delta) << 1 ^ uint32_t(delta >> 31));  // zigzag: small |delta| -> small code
      previous = current;
    }
  }
  w.finish();
  return out;
}

std::vector<uint16_t> decode_rvl(std::span<const uint8_t> bytes, int width, int height) {
  check_size(width, height, "RVL decode");
  const int64_t n = int64_t(width) * int64_t(height);
  if (bytes.size() % 4 != 0)
    throw std::invalid_argument("depth: RVL stream is " + std::to_string(bytes.size()) +
                                " bytes, not a whole number of 32-bit words");
  std::vector<uint16_t> out(size_t(n), 0);
  NibbleReader r(bytes, n);
  int64_t i = 0;
  int32_t previous = 0;
  while (i < n) {
    const uint64_t zeros = r.get(i);
    if (zeros > uint64_t(n - i))
      throw std::invalid_argument("depth: RVL zero run of " + std::to_string(zeros) + " at pixel " +
                                  std::to_string(i) + " runs past the last pixel" + r.where());
    i += int64_t(zeros);  // `out` is already zero
    const uint64_t nonzeros = r.get(i);
    if (nonzeros > uint64_t(n - i))
      throw std::invalid_argument("depth: RVL value run of " + std::to_string(nonzeros) + " at pixel " +
                                  std::to_string(i) + " runs past the last pixel" + r.where());
    // Runs are maximal: only the first zero run and the last value run can be empty.
    if (zeros == 0 && i > 0)
      throw std::invalid_argument("depth: RVL empty zero run at pixel " + std::to_string(i) + r.where());
    if (nonzeros == 0 && i < n)
      throw std::invalid_argument("depth: RVL empty value run at pixel " + std::to_string(i) + r.where());
    for (uint64_t k = 0; k < nonzeros; ++k, ++i) {
      const uint64_t code = r.get(i);
      if (code > 0x1ffffu)  // |delta| <= 65535 folds to at most 131070
        throw std::invalid_argument("depth: RVL delta code " + std::to_string(code) + " out of range at pixel " +
                                    std::to_string(i) + r.where());
      const int32_t delta = int32_t(code >> 1) ^ -int32_t(code & 1u);
      const int32_t current = previous + delta;
      if (current < 1 || current > 0xffff)
        throw std::invalid_argument("depth: RVL value " + std::to_string(current) + " at pixel " + std::to_string(i) +
                                    " is outside 1..65535" + r.where());
      out[size_t(i)] = uint16_t(current);
      previous = current;
    }
  }
  r.expect_end(n);
  return out;
}

std::vector<uint8_t> encode_rvl_zstd(std::span<const uint16_t> depth, int width, int height, int zstd_level) {
  if (zstd_level < 1 || zstd_level > 19)
    throw std::invalid_argument("depth: zstd level must be 1..19, got " + std::to_string(zstd_level));
  const std::vector<uint8_t> rvl = encode_rvl(depth, width, height);
  std::vector<uint8_t> out(ZSTD_compressBound(rvl.size()));
  // One frame with its content size and a content checksum, so corruption is caught by zstd.
  const std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> cctx(ZSTD_createCCtx(), ZSTD_freeCCtx);
  if (!cctx) throw std::runtime_error("depth: cannot create a zstd context");
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, zstd_level);
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_checksumFlag, 1);
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_contentSizeFlag, 1);
  const size_t size = ZSTD_compress2(cctx.get(), out.data(), out.size(), rvl.data(), rvl.size());
  if (ZSTD_isError(size)) throw std::runtime_error(std::string("depth: zstd compression failed: ") + ZSTD_getErrorName(size));
  out.resize(size);
  return out;
}

std::vector<uint16_t> decode_rvl_zstd(std::span<const uint8_t> bytes, int width, int height) {
  check_size(width, height, "RVL+zstd decode");
  const int64_t n = int64_t(width) * int64_t(height);
  const unsigned long long content = ZSTD_getFrameContentSize(bytes.data(), bytes.size());
  if (content == ZSTD_CONTENTSIZE_ERROR)
    throw std::invalid_argument("depth: RVL+zstd data is not a zstd frame (" + std::to_string(bytes.size()) + " bytes)");
  if (content == ZSTD_CONTENTSIZE_UNKNOWN)
    throw std::invalid_argument("depth: RVL+zstd frame does not state its content size");
  if (content > uint64_t(rvl_max_bytes(n)))
    throw std::invalid_argument("depth: RVL+zstd frame claims " + std::to_string(content) +
                                " bytes, more than any RVL stream of " + std::to_string(n) + " pixels");
  const size_t frame = ZSTD_findFrameCompressedSize(bytes.data(), bytes.size());
  if (ZSTD_isError(frame))
    throw std::invalid_argument(std::string("depth: RVL+zstd frame is corrupt: ") + ZSTD_getErrorName(frame));
  if (frame != bytes.size())
    throw std::invalid_argument("depth: RVL+zstd data has " + std::to_string(bytes.size() - frame) +
                                " bytes after the zstd frame");
  std::vector<uint8_t> rvl(static_cast<size_t>(content));
  const size_t got = ZSTD_decompress(rvl.data(), rvl.size(), bytes.data(), bytes.size());
  if (ZSTD_isError(got))
    throw std::invalid_argument(std::string("depth: RVL+zstd frame is corrupt: ") + ZSTD_getErrorName(got));
  if (got != rvl.size())
    throw std::invalid_argument("depth: RVL+zstd frame holds " + std::to_string(got) + " bytes, its header says " +
                                std::to_string(content));
  return decode_rvl(rvl, width, height);
}

}  // namespace rrg::io
