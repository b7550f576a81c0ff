// RVL and RVL+zstd: a hand-computed stream, exact round trips on real 7-Scenes depth and on
// synthetic worst cases, and corrupt input (every truncation, bit flips) that must throw
// std::invalid_argument and never crash or over-read (run under ASan by tests/fuzz as well).
#include "core/io/image_io.h"
#include "core/io/rvl.h"

#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

namespace rrg::io {
namespace {

std::vector<uint16_t> real_depth(int frame, int& w, int& h) {
  char name[64];
  std::snprintf(name, sizeof(name), "7scenes_mini/frame-%06d.depth.png", frame);
  const Image<uint16_t> d = read_depth_raw(test::test_data_dir() / name);
  w = d.width();
  h = d.height();
  return {d.data(), d.data() + d.size()};
}

TEST(Rvl, HandComputedStream) {
  // [0 0 5 3]: zeros 2 -> nibble 2; non-zeros 2 -> 2; delta +5 -> zigzag 10 = 0b1'010 -> nibbles
  // 0xA (010 + more), 0x1; delta -2 -> zigzag 3 -> 0x3. Word 0x22A13000, stored little-endian.
  const std::vector<uint16_t> d{0, 0, 5, 3};
  const auto bytes = encode_rvl(d, 4, 1);
  EXPECT_EQ(bytes, (std::vector<uint8_t>{0x00, 0x30, 0xA1, 0x22}));
  EXPECT_EQ(decode_rvl(bytes, 4, 1), d);
  EXPECT_EQ(decode_rvl(bytes, 2, 2), d);  // only the pixel count matters
}

TEST(Rvl, EmptyImageIsAnEmptyStream) {
  EXPECT_TRUE(encode_rvl({}, 0, 0).empty());
  EXPECT_TRUE(decode_rvl({}, 0, 5).empty());
  const std::vector<uint8_t> word{0, 0, 0, 0};
  EXPECT_THROW(decode_rvl(word, 0, 0), std::invalid_argument);  // trailing word
}

TEST(Rvl, RoundTripOnReal7ScenesDepth) {
  for (int f = 0; f < 3; ++f) {
    int w = 0, h = 0;
    const auto depth = real_depth(f, w, h);
    const auto rvl = encode_rvl(depth, w, h);
    EXPECT_EQ(decode_rvl(rvl, w, h), depth) << "frame " << f;
    const auto z = encode_rvl_zstd(depth, w, h);
    EXPECT_EQ(decode_rvl_zstd(z, w, h), depth) << "frame " << f;
    // RVL is a compressor: far below the 2 bytes per pixel of raw uint16 on real sensor depth.
    EXPECT_LT(rvl.size(), depth.size()) << "frame " << f;
    std::printf("7-Scenes frame %d (%dx%d): raw %zu B, RVL %zu B (%.2fx), RVL+zstd %zu B (%.2fx)\n", f, w, h,
                2 * depth.size(), rvl.size(), 2.0 * depth.size() / rvl.size(), z.size(), 2.0 * depth.size() / z.size());
  }
}

std::vector<std::vector<uint16_t>> worst_cases(int n) {
  std::vector<std::vector<uint16_t>> cases;
  cases.emplace_back(n, 0);       // one long zero run
  cases.emplace_back(n, 65535);   // one long value run, first delta +65535
  cases.emplace_back(n, 1);
  std::vector<uint16_t> alt(n), swing(n), ramp(n), rnd(n);
  std::mt19937 rng(7);
  for (int i = 0; i < n; ++i) {
    alt[i] = i % 2 ? 65535 : 0;           // runs of one, largest codes
    swing[i] = i % 2 ? 65535 : 1;         // deltas of +-65534, 6-nibble codes
    ramp[i] = uint16_t(i * 37);           // wraps through 0 now and then
    rnd[i] = rng() % 3 == 0 ? 0 : uint16_t(rng());
  }
  for (auto* v : {&alt, &swing, &ramp, &rnd}) cases.push_back(*v);
  return cases;
}

TEST(Rvl, RoundTripOnWorstCases) {
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {7, 1}, {1, 9}, {64, 48}}) {
    int k = 0;
    for (const auto& d : worst_cases(w * h)) {
      const auto rvl = encode_rvl(d, w, h);
      ASSERT_EQ(decode_rvl(rvl, w, h), d) << w << "x" << h << " case " << k;
      ASSERT_LE(int64_t(rvl.size()), rvl_max_bytes(int64_t(w) * h)) << w << "x" << h << " case " << k;
      ASSERT_EQ(decode_rvl_zstd(encode_rvl_zstd(d, w, h, 19), w, h), d) << w << "x" << h << " case " << k;
      ++k;
    }
  }
}

TEST(Rvl, EncodeChecksItsInput) {
  const std::vector<uint16_t> d(6, 1);
  EXPECT_THROW(encode_rvl(d, 4, 1), std::invalid_argument);
  EXPECT_THROW(encode_rvl(d, -1, -6), std::invalid_argument);
  EXPECT_THROW(encode_rvl_zstd(d, 6, 1, 0), std::invalid_argument);
  EXPECT_THROW(decode_rvl({}, 1 << 15, 1 << 15), std::invalid_argument);  // beyond kMaxCodecPixels
}

TEST(Rvl, EveryTruncationThrows) {
  for (const auto& d : worst_cases(40)) {
    for (const bool zstd : {false, true}) {
      const auto full = zstd ? encode_rvl_zstd(d, 8, 5) : encode_rvl(d, 8, 5);
      for (size_t len = 0; len < full.size(); ++len) {
        const std::span<const uint8_t> cut(full.data(), len);
        EXPECT_THROW(zstd ? decode_rvl_zstd(cut, 8, 5) : decode_rvl(cut, 8, 5), std::invalid_argument)
            << (zstd ? "rvl+zstd" : "rvl") << " cut at " << len << " of " << full.size();
      }
    }
  }
}

TEST(Rvl, TruncationMessageNamesThePixel) {
  const std::vector<uint16_t> d(100, 1000);
  auto bytes = encode_rvl(d, 10, 10);
  bytes.resize(8);
  try {
    decode_rvl(bytes, 10, 10);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("depth: RVL stream truncated at pixel"), std::string::npos) << e.what();
  }
}

TEST(Rvl, StructuralCorruptionIsRejected) {
  auto word = [](uint32_t w) { return std::vector<uint8_t>{uint8_t(w), uint8_t(w >> 8), uint8_t(w >> 16), uint8_t(w >> 24)}; };
  // zeros = 5 for a 4-pixel image: runs past the end.
  EXPECT_THROW(decode_rvl(word(0x50000000), 4, 1), std::invalid_argument);
  // an empty run pair (0 zeros, 0 values) with pixels left.
  EXPECT_THROW(decode_rvl(word(0x00000000), 4, 1), std::invalid_argument);
  // value 0 inside a value run: zeros 0, values 1, code 0 (delta 0 from the start value 0).
  EXPECT_THROW(decode_rvl(word(0x01000000), 1, 1), std::invalid_argument);
  // negative value: code 1 = delta -1.
  EXPECT_THROW(decode_rvl(word(0x01100000), 1, 1), std::invalid_argument);
  // a valid 1-pixel stream (0, 1, code 2 = value 1) with non-zero padding, then with a trailing word.
  EXPECT_EQ(decode_rvl(word(0x01200000), 1, 1), std::vector<uint16_t>{1});
  EXPECT_THROW(decode_rvl(word(0x01200001), 1, 1), std::invalid_argument);
  auto two = word(0x01200000);
  two.insert(two.end(), 4, 0);
  EXPECT_THROW(decode_rvl(two, 1, 1), std::invalid_argument);
  // an over-long code: twelve continuation nibbles.
  auto longcode = word(0x88888888);
  const auto more = word(0x88880000);
  longcode.insert(longcode.end(), more.begin(), more.end());
  EXPECT_THROW(decode_rvl(longcode, 1, 1), std::invalid_argument);
  // 3 bytes: not whole words.
  EXPECT_THROW(decode_rvl(std::vector<uint8_t>{1, 2, 3}, 1, 1), std::invalid_argument);
}

TEST(Rvl, RandomBitFlipsThrowOrDecode) {
  std::mt19937 rng(11);
  int threw_rvl = 0, threw_zstd = 0, trials = 0;
  for (const auto& d : worst_cases(24 * 16)) {
    const auto rvl = encode_rvl(d, 24, 16);
    const auto z = encode_rvl_zstd(d, 24, 16);
    for (int t = 0; t < 300; ++t, ++trials) {
      auto a = rvl, b = z;
      a[rng() % a.size()] ^= uint8_t(1u << (rng() % 8));
      b[rng() % b.size()] ^= uint8_t(1u << (rng() % 8));
      try {
        EXPECT_EQ(decode_rvl(a, 24, 16).size(), d.size());  // a flip can give another valid stream
      } catch (const std::invalid_argument&) {
        ++threw_rvl;
      }
      try {
        // zstd's content checksum: a corrupted frame either fails or yields exactly the original.
        EXPECT_EQ(decode_rvl_zstd(b, 24, 16), d);
      } catch (const std::invalid_argument&) {
        ++threw_zstd;
      }
    }
  }
  std::printf("bit flips: %d trials, RVL rejected %d, RVL+zstd rejected %d\n", trials, threw_rvl, threw_zstd);
  EXPECT_GT(threw_zstd, trials / 2);
}

TEST(Rvl, ZstdLayerRejectsForeignAndBombFrames) {
  const std::vector<uint16_t> d(16, 300);
  auto z = encode_rvl_zstd(d, 4, 4);
  EXPECT_THROW(decode_rvl_zstd(z, 2, 2), std::invalid_argument);  // content is a 16-pixel stream
  auto extra = z;
  extra.push_back(0);
  EXPECT_THROW(decode_rvl_zstd(extra, 4, 4), std::invalid_argument);  // bytes after the frame
  // A frame claiming far more content than any 4x4 RVL stream: refused before allocating.
  const std::vector<uint16_t> big(512 * 512, 7);
  const auto bomb = encode_rvl_zstd(big, 512, 512);
  EXPECT_THROW(decode_rvl_zstd(bomb, 4, 4), std::invalid_argument);
  EXPECT_THROW(decode_rvl_zstd(std::vector<uint8_t>{'n', 'o', 't', 'z', 's', 't', 'd'}, 4, 4), std::invalid_argument);
}

}  // namespace
}  // namespace rrg::io
