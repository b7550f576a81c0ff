// PNG IHDR (PNG spec §11.2.2) and JPEG SOFn (ITU T.81 §B.2.2) parsing, every read bounds-checked.
#include "core/io/image_header.h"

#include <stdexcept>
#include <string>

namespace rrg::io {
namespace {

uint32_t be16(std::span<const uint8_t> b, size_t at) { return uint32_t(b[at]) << 8 | b[at + 1]; }
uint32_t be32(std::span<const uint8_t> b, size_t at) { return be16(b, at) << 16 | be16(b, at + 2); }

std::string hex_byte(uint8_t b) {
  static constexpr char kDigits[] = "0123456789abcdef";
  return std::string("0x") + kDigits[b >> 4] + kDigits[b & 15];
}

[[noreturn]] void fail(std::string_view field, const std::string& what) {
  throw std::invalid_argument(std::string(field) + ": " + what);
}

}  // namespace

ImageHeader read_png_header(std::span<const uint8_t> bytes, std::string_view field) {
  static constexpr uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  // signature (8) + chunk length (4) + "IHDR" (4) + 13 data bytes
  if (bytes.size() < 29) fail(field, "PNG data too short (" + std::to_string(bytes.size()) + " bytes)");
  for (int i = 0; i < 8; ++i)
    if (bytes[size_t(i)] != kSignature[i]) fail(field, "not a PNG file (bad signature)");
  if (be32(bytes, 8) != 13 || bytes[12] != 'I' || bytes[13] != 'H' || bytes[14] != 'D' || bytes[15] != 'R')
    fail(field, "PNG does not start with an IHDR chunk");
  const uint32_t w = be32(bytes, 16), h = be32(bytes, 20);
  if (w == 0 || h == 0 || w > 0x7fffffffu || h > 0x7fffffffu)
    fail(field, "PNG declares an invalid size " + std::to_string(w) + "x" + std::to_string(h));
  return {int(w), int(h), int(bytes[24]), int(bytes[25])};
}

ImageHeader read_jpeg_header(std::span<const uint8_t> bytes, std::string_view field) {
  if (bytes.size() < 4 || bytes[0] != 0xff || bytes[1] != 0xd8) fail(field, "not a JPEG file (no SOI marker)");
  size_t pos = 2;
  while (true) {
    if (pos >= bytes.size() || bytes[pos] != 0xff)
      fail(field, "JPEG marker expected at byte " + std::to_string(pos) + " (no frame header found)");
    while (pos < bytes.size() && bytes[pos] == 0xff) ++pos;  // fill bytes
    if (pos >= bytes.size()) fail(field, "JPEG truncated before its frame header");
    const uint8_t marker = bytes[pos++];
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) continue;  // TEM, RSTn: no length
    if (marker == 0xd8 || marker == 0xd9 || marker == 0xda || marker == 0x00)
      fail(field, "JPEG has no frame header before marker " + hex_byte(marker));
    if (bytes.size() - pos < 2) fail(field, "JPEG truncated in a segment length at byte " + std::to_string(pos));
    const uint32_t len = be16(bytes, pos);
    if (len < 2 || bytes.size() - pos < len)
      fail(field, "JPEG segment at byte " + std::to_string(pos) + " has a bad length " + std::to_string(len));
    const bool sof = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (sof) {
      if (len < 8) fail(field, "JPEG frame header too short");
      const int precision = bytes[pos + 2];
      const uint32_t h = be16(bytes, pos + 3), w = be16(bytes, pos + 5);
      if (w == 0 || h == 0)
        fail(field, "JPEG declares an invalid size " + std::to_string(w) + "x" + std::to_string(h));
      return {int(w), int(h), precision, int(bytes[pos + 7])};
    }
    pos += len;
  }
}

}  // namespace rrg::io
