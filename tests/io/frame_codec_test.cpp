// Frame codec: every colour and depth form round-trips (exactly where lossless), real 7-Scenes
// frames decode to what the dataset reader sees, and every bad input (wrong size, wrong form,
// truncation at every byte, bit flips, NaN / negative depth, absurd intrinsics) is refused with a
// std::invalid_argument naming the field.
#include "core/io/frame_codec.h"
#include "core/io/image_io.h"

#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>

namespace rrg::io {
namespace {

std::vector<uint8_t> file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Expects `f` to throw std::invalid_argument whose message contains every one of `parts`.
template <class F>
void expect_error(F&& f, std::initializer_list<const char*> parts) {
  try {
    f();
    ADD_FAILURE() << "no exception, expected one containing '" << *parts.begin() << "'";
  } catch (const std::invalid_argument& e) {
    for (const char* p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

ColorImage test_color(int w, int h) {  // smooth gradients with 8-bit exact values
  ColorImage c(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      c(x, y) = Color(float((x * 7) % 256), float((y * 5) % 256), float((x + y) % 256)) * (1.0f / 255.0f);
  return c;
}

DepthImage test_depth(int w, int h, float scale) {  // values on the scale's grid, some holes
  DepthImage d(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d(x, y) = ((x * 3 + y) % 11 == 0) ? 0.0f : float(500 + x * 13 + y * 7) / scale;
  return d;
}

const std::vector<DepthEncoding> kLossless16 = {DepthEncoding::raw_u16, DepthEncoding::png_u16, DepthEncoding::rvl,
                                                DepthEncoding::rvl_zstd};

TEST(FrameCodec, NamesRoundTrip) {
  for (auto e : {ColorEncoding::raw_rgb8, ColorEncoding::png, ColorEncoding::jpeg})
    EXPECT_EQ(parse_color_encoding(to_string(e)), e);
  for (auto e : {DepthEncoding::raw_u16, DepthEncoding::png_u16, DepthEncoding::rvl, DepthEncoding::rvl_zstd,
                 DepthEncoding::raw_f32})
    EXPECT_EQ(parse_depth_encoding(to_string(e)), e);
  expect_error([] { parse_color_encoding("webp"); }, {"color: unknown encoding 'webp'"});
  expect_error([] { parse_depth_encoding("exr"); }, {"depth: unknown encoding 'exr'"});
}

TEST(FrameCodec, ColorRoundTrips) {
  const ColorImage c = test_color(33, 21);
  for (auto e : {ColorEncoding::raw_rgb8, ColorEncoding::png}) {
    const ColorImage out = decode_color(encode_color(c, e), e, 33, 21);
    for (size_t i = 0; i < c.size(); ++i) ASSERT_EQ(out[i], c[i]) << to_string(e) << " pixel " << i;
  }
  FrameEncodeOptions o;
  o.jpeg_quality = 95;
  const ColorImage j = decode_color(encode_color(c, ColorEncoding::jpeg, o), ColorEncoding::jpeg, 33, 21);
  double err = 0;
  for (size_t i = 0; i < c.size(); ++i) err += (j[i] - c[i]).cwiseAbs().sum() / 3.0;
  EXPECT_LT(err / double(c.size()), 0.05);  // lossy, but the same picture
}

TEST(FrameCodec, Real7ScenesFramesDecodeLikeTheDatasetReader) {
  const auto dir = test::test_data_dir() / "7scenes_mini";
  const ColorImage ref = read_color(dir / "frame-000000.color.jpg");
  const ColorImage c = decode_color(file_bytes(dir / "frame-000000.color.jpg"), ColorEncoding::jpeg, 640, 480);
  for (size_t i = 0; i < c.size(); ++i) ASSERT_EQ(c[i], ref[i]) << "pixel " << i;
  const DepthImage dref = read_depth(dir / "frame-000000.depth.png", 1000.0f);
  const DepthImage d = decode_depth(file_bytes(dir / "frame-000000.depth.png"), DepthEncoding::png_u16, 640, 480, 1000.0f);
  for (size_t i = 0; i < d.size(); ++i) ASSERT_EQ(d[i], dref[i]) << "pixel " << i;
  // ... and every lossless form carries the same stored values.
  const Image<uint16_t> raw = read_depth_raw(dir / "frame-000000.depth.png");
  for (auto e : kLossless16) {
    const Image<uint16_t> out = decode_u16_image(encode_u16_image(raw, e), e, 640, 480, "depth");
    ASSERT_EQ(std::memcmp(out.data(), raw.data(), raw.size() * 2), 0) << to_string(e);
  }
}

TEST(FrameCodec, DepthRoundTripsInEveryForm) {
  const float scale = 5000.0f;
  const DepthImage d = test_depth(40, 30, scale);
  for (auto e : kLossless16) {
    const DepthImage out = decode_depth(encode_depth(d, e, scale), e, 40, 30, scale);
    for (size_t i = 0; i < d.size(); ++i) ASSERT_NEAR(out[i], d[i], 1e-7f) << to_string(e) << " pixel " << i;
  }
  const DepthImage f = decode_depth(encode_depth(d, DepthEncoding::raw_f32, scale), DepthEncoding::raw_f32, 40, 30, scale);
  for (size_t i = 0; i < d.size(); ++i) ASSERT_EQ(f[i], d[i]);
  // Out-of-range, negative and NaN metres are encoded as holes.
  DepthImage odd(3, 1);
  odd[0] = 20.0f;  // 100000 at scale 5000: does not fit uint16
  odd[1] = -1.0f;
  odd[2] = std::numeric_limits<float>::quiet_NaN();
  for (auto e : {DepthEncoding::rvl, DepthEncoding::raw_f32}) {
    const DepthImage out = decode_depth(encode_depth(odd, e, scale), e, 3, 1, scale);
    EXPECT_EQ(out[1], 0.0f);
    EXPECT_EQ(out[2], 0.0f);
    if (e == DepthEncoding::rvl) EXPECT_EQ(out[0], 0.0f);
  }
}

TEST(FrameCodec, WrongSizesNameFieldAndSizes) {
  const ColorImage c = test_color(32, 24);
  expect_error([&] { decode_color(encode_color(c, ColorEncoding::jpeg), ColorEncoding::jpeg, 16, 24); },
               {"color: JPEG is 32x24, session expects 16x24"});
  expect_error([&] { decode_color(encode_color(c, ColorEncoding::png), ColorEncoding::png, 32, 12); },
               {"color: PNG is 32x24, session expects 32x12"});
  expect_error([&] { decode_color(encode_color(c, ColorEncoding::raw_rgb8), ColorEncoding::raw_rgb8, 32, 25); },
               {"color: raw RGB8 data is 2304 bytes, a 32x25 image needs 2400"});
  const DepthImage d = test_depth(32, 24, 1000.0f);
  expect_error([&] { decode_depth(encode_depth(d, DepthEncoding::png_u16, 1000), DepthEncoding::png_u16, 31, 24, 1000); },
               {"depth: PNG is 32x24, session expects 31x24"});
  expect_error([&] { decode_depth(encode_depth(d, DepthEncoding::raw_u16, 1000), DepthEncoding::raw_u16, 32, 23, 1000); },
               {"depth: raw uint16 data is"});
  expect_error([&] { decode_depth(encode_depth(d, DepthEncoding::rvl, 1000), DepthEncoding::rvl, 32, 23, 1000); },
               {"depth: RVL"});
  expect_error([&] { decode_depth(encode_depth(d, DepthEncoding::rvl, 1000), DepthEncoding::rvl, 0, 23, 1000); },
               {"depth: image size 0x23 must be positive"});
}

TEST(FrameCodec, WrongFormsAreRefused) {
  const ColorImage c = test_color(16, 8);
  const auto png = encode_color(c, ColorEncoding::png);
  const auto jpg = encode_color(c, ColorEncoding::jpeg);
  expect_error([&] { decode_color(png, ColorEncoding::jpeg, 16, 8); }, {"color: not a JPEG"});
  expect_error([&] { decode_color(jpg, ColorEncoding::png, 16, 8); }, {"color: not a PNG"});
  // A colour PNG (8-bit RGB) is not a depth map.
  expect_error([&] { decode_depth(png, DepthEncoding::png_u16, 16, 8, 1000); }, {"depth: PNG is 8-bit colour type 2"});
  expect_error([&] { decode_u16_image(png, DepthEncoding::raw_f32, 16, 8, "labels"); }, {"labels: raw_f32"});
  // Labels name their own field in RVL errors.
  expect_error([&] { decode_u16_image(std::vector<uint8_t>{0, 0, 0, 0}, DepthEncoding::rvl, 2, 2, "labels"); },
               {"labels: RVL"});
  expect_error([] { decode_depth({}, DepthEncoding::rvl, 2, 2, 0.0f); }, {"depth: depth_scale must be positive"});
  expect_error([] { decode_depth({}, DepthEncoding::rvl, 2, 2, std::nanf("")); }, {"depth: depth_scale"});
}

TEST(FrameCodec, RawFloatDepthRejectsNaNInfinityAndNegative) {
  auto bytes_of = [](std::vector<float> v) {
    std::vector<uint8_t> b(v.size() * 4);
    std::memcpy(b.data(), v.data(), b.size());
    return b;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  expect_error([&] { decode_depth(bytes_of({1, 2, nan, 0}), DepthEncoding::raw_f32, 2, 2, 1); }, {"depth: NaN at pixel 2"});
  expect_error([&] { decode_depth(bytes_of({1, inf, 1, 0}), DepthEncoding::raw_f32, 2, 2, 1); }, {"depth: infinite value at pixel 1"});
  expect_error([&] { decode_depth(bytes_of({1, 2, 3, -0.5f}), DepthEncoding::raw_f32, 2, 2, 1); },
               {"depth: negative value", "at pixel 3"});
  const DepthImage ok = decode_depth(bytes_of({1, 2, 3, 0}), DepthEncoding::raw_f32, 2, 2, 1);
  EXPECT_EQ(ok[2], 3.0f);
}

TEST(FrameCodec, IntrinsicsAreChecked) {
  const Intrinsics good{525, 525, 319.5f, 239.5f, 640, 480};
  EXPECT_NO_THROW(validate_intrinsics(good));
  auto with = [&](auto change) {
    Intrinsics k = good;
    change(k);
    return k;
  };
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.fx = 0; })); }, {"intrinsics: fx must be positive"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.fy = -3; })); }, {"intrinsics: fy must be positive"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.fx = std::nanf(""); })); }, {"intrinsics: fx"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.fx = 10; })); }, {"intrinsics: fx", "field of view"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.fy = 1e7f; })); }, {"intrinsics: fy", "field of view"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.cx = 700; })); }, {"intrinsics: cx"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.cy = -2; })); }, {"intrinsics: cy"});
  expect_error([&] { validate_intrinsics(with([](Intrinsics& k) { k.width = 0; })); }, {"intrinsics: image size"});
}

// Every truncation of a small encoded frame is refused (the full frame decodes).
TEST(FrameCodec, EveryTruncationThrows) {
  const int w = 12, h = 9;
  const ColorImage c = test_color(w, h);
  const DepthImage d = test_depth(w, h, 1000.0f);
  for (auto e : {ColorEncoding::raw_rgb8, ColorEncoding::png, ColorEncoding::jpeg}) {
    const auto full = encode_color(c, e);
    ASSERT_NO_THROW(decode_color(full, e, w, h));
    for (size_t len = 0; len < full.size(); ++len)
      EXPECT_THROW(decode_color(std::span<const uint8_t>(full.data(), len), e, w, h), std::invalid_argument)
          << to_string(e) << " cut at " << len << " of " << full.size();
  }
  for (auto e : {DepthEncoding::raw_u16, DepthEncoding::png_u16, DepthEncoding::rvl, DepthEncoding::rvl_zstd,
                 DepthEncoding::raw_f32}) {
    const auto full = encode_depth(d, e, 1000.0f);
    ASSERT_NO_THROW(decode_depth(full, e, w, h, 1000.0f));
    for (size_t len = 0; len < full.size(); ++len)
      EXPECT_THROW(decode_depth(std::span<const uint8_t>(full.data(), len), e, w, h, 1000.0f), std::invalid_argument)
          << to_string(e) << " cut at " << len << " of " << full.size();
  }
}

// Random bit flips: a flipped frame is refused or decodes to an image of the session's size;
// never a crash (ASan runs of this and of tests/fuzz check for over-reads).
TEST(FrameCodec, RandomBitFlipsThrowOrDecode) {
  const int w = 16, h = 12;
  std::mt19937 rng(3);
  const ColorImage c = test_color(w, h);
  const DepthImage d = test_depth(w, h, 1000.0f);
  int rejected = 0, trials = 0;
  auto flip = [&](std::vector<uint8_t> b) {
    const int flips = 1 + int(rng() % 3);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] ^= uint8_t(1u << (rng() % 8));
    return b;
  };
  for (auto e : {ColorEncoding::png, ColorEncoding::jpeg}) {
    const auto full = encode_color(c, e);
    for (int t = 0; t < 400; ++t, ++trials) try {
        const ColorImage out = decode_color(flip(full), e, w, h);
        EXPECT_TRUE(out.width() == w && out.height() == h);
      } catch (const std::invalid_argument&) {
        ++rejected;
      }
  }
  for (auto e : {DepthEncoding::png_u16, DepthEncoding::rvl, DepthEncoding::rvl_zstd}) {
    const auto full = encode_depth(d, e, 1000.0f);
    for (int t = 0; t < 400; ++t, ++trials) try {
        const DepthImage out = decode_depth(flip(full), e, w, h, 1000.0f);
        EXPECT_TRUE(out.width() == w && out.height() == h);
        for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(std::isfinite(out[i]) && out[i] >= 0.0f);
      } catch (const std::invalid_argument&) {
        ++rejected;
      }
  }
  std::printf("frame bit flips: %d trials, %d rejected\n", trials, rejected);
}

}  // namespace
}  // namespace rrg::io
