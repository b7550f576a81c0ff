// The fuzz target's body and its seed inputs (shared by the libFuzzer build and test_fuzz).
#include "tests/fuzz/frame_fuzz.h"

#include "core/io/frame_codec.h"
#include "core/io/rvl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <stdexcept>

namespace rrg::fuzz {
namespace {

using io::ColorEncoding;
using io::DepthEncoding;

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "frame fuzz finding: %s\n", what);
  std::abort();
}

}  // namespace

bool decode_frame_input(const uint8_t* data, size_t size) {
  if (size < 3) return false;
  const int mode = data[0] % kFuzzModes;
  const int w = 1 + data[1] % 48, h = 1 + data[2] % 48;
  const std::span<const uint8_t> payload(data + 3, size - 3);
  try {
    switch (mode) {
      case 0: case 1: case 2: {
        const ColorEncoding e = mode == 0 ? ColorEncoding::raw_rgb8 : mode == 1 ? ColorEncoding::png : ColorEncoding::jpeg;
        const ColorImage c = io::decode_color(payload, e, w, h);
        if (c.width() != w || c.height() != h) finding("colour image of the wrong size");
        for (size_t i = 0; i < c.size(); ++i)
          if (!(c[i].minCoeff() >= 0.0f && c[i].maxCoeff() <= 1.0f)) finding("colour outside [0,1]");
        return true;
      }
      case 3: case 4: case 5: case 6: case 7: {
        const DepthEncoding e = mode == 3 ? DepthEncoding::raw_u16 : mode == 4 ? DepthEncoding::png_u16
                                : mode == 5 ? DepthEncoding::rvl : mode == 6 ? DepthEncoding::rvl_zstd
                                            : DepthEncoding::raw_f32;
        const DepthImage d = io::decode_depth(payload, e, w, h, 1000.0f);
        if (d.width() != w || d.height() != h) finding("depth image of the wrong size");
        for (size_t i = 0; i < d.size(); ++i)
          if (!(std::isfinite(d[i]) && d[i] >= 0.0f)) finding("depth NaN, infinite or negative");
        if (e == DepthEncoding::rvl) {  // accepted RVL streams are canonical
          std::vector<uint16_t> raw(d.size());
          for (size_t i = 0; i < d.size(); ++i) raw[i] = uint16_t(std::lround(d[i] * 1000.0f));
          const auto again = io::encode_rvl(raw, w, h);
          if (again.size() != payload.size() || !std::equal(again.begin(), again.end(), payload.begin()))
            finding("an accepted RVL stream does not re-encode to itself");
        }
        return true;
      }
      default: {
        const Image<uint16_t> l = io::decode_u16_image(payload, DepthEncoding::rvl, w, h, "labels");
        if (l.width() != w || l.height() != h) finding("label image of the wrong size");
        return true;
      }
    }
  } catch (const std::invalid_argument&) {
    return false;  // the one allowed failure
  }
}

std::vector<std::vector<uint8_t>> frame_fuzz_seeds() {
  std::vector<std::vector<uint8_t>> seeds;
  auto add = [&](int mode, int w, int h, const std::vector<uint8_t>& payload) {
    std::vector<uint8_t> s{uint8_t(mode), uint8_t(w - 1), uint8_t(h - 1)};
    s.insert(s.end(), payload.begin(), payload.end());
    seeds.push_back(std::move(s));
  };
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{5, 3}, std::pair{16, 12}, std::pair{47, 31}}) {
    ColorImage c(w, h);
    DepthImage d(w, h);
    Image<uint16_t> labels(w, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        c(x, y) = Color(float(x) / w, float(y) / h, float((x * y) % 7) / 7.0f);
        d(x, y) = (x + 2 * y) % 5 == 0 ? 0.0f : 0.5f + 0.013f * float(x) + 0.007f * float(y);
        labels(x, y) = uint16_t(x < w / 2 ? 0 : 1 + y % 3);
      }
    add(0, w, h, io::encode_color(c, ColorEncoding::raw_rgb8));
    add(1, w, h, io::encode_color(c, ColorEncoding::png));
    add(2, w, h, io::encode_color(c, ColorEncoding::jpeg));
    add(3, w, h, io::encode_depth(d, DepthEncoding::raw_u16, 1000.0f));
    add(4, w, h, io::encode_depth(d, DepthEncoding::png_u16, 1000.0f));
    add(5, w, h, io::encode_depth(d, DepthEncoding::rvl, 1000.0f));
    add(6, w, h, io::encode_depth(d, DepthEncoding::rvl_zstd, 1000.0f));
    add(7, w, h, io::encode_depth(d, DepthEncoding::raw_f32, 1000.0f));
    add(8, w, h, io::encode_u16_image(labels, DepthEncoding::rvl));
  }
  return seeds;
}

}  // namespace rrg::fuzz
