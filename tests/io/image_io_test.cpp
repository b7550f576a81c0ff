// Image files: round trips at the stated precision, channel order, and errors naming the file.
#include "core/io/image_io.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

// Expects f() to throw std::runtime_error whose message contains every fragment.
template <class F>
void expect_error(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    for (const auto& frag : fragments) EXPECT_NE(std::string(e.what()).find(frag), std::string::npos) << e.what();
  }
}

TEST(ImageIo, ColorRoundTripIsExactAfterQuantisation) {
  test::TempDir dir("io-img");
  ColorImage img(7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) img(x, y) = Color(x / 6.0f, y / 4.0f, 0.3f + 0.01f * x);
  img(0, 0) = Color(-0.5f, 2.0f, std::nanf(""));  // clamped, NaN -> 0
  write_color_png(dir / "c.png", img);
  const ColorImage back = read_color(dir / "c.png");
  ASSERT_EQ(back.width(), 7);
  ASSERT_EQ(back.height(), 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      if (x == 0 && y == 0) continue;
      for (int k = 0; k < 3; ++k) {
        const float q = std::round(img(x, y)[k] * 255.0f) / 255.0f;  // expected 8-bit value
        EXPECT_FLOAT_EQ(back(x, y)[k], q) << x << "," << y << "," << k;
      }
    }
  EXPECT_EQ(back(0, 0), Color(0.0f, 1.0f, 0.0f));
  // Writing again from the read image reproduces the bytes' values exactly.
  write_color_png(dir / "c2.png", back);
  const ColorImage again = read_color(dir / "c2.png");
  for (size_t i = 0; i < back.size(); ++i) EXPECT_EQ(again[i], back[i]);
}

TEST(ImageIo, ColorIsRgbNotBgr) {
  test::TempDir dir("io-img");
  cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(10, 20, 250));  // B=10, G=20, R=250
  ASSERT_TRUE(cv::imwrite((dir / "bgr.png").string(), bgr));
  const ColorImage c = read_color(dir / "bgr.png");
  EXPECT_FLOAT_EQ(c(0, 0).x(), 250.0f / 255.0f);
  EXPECT_FLOAT_EQ(c(0, 0).z(), 10.0f / 255.0f);
}

TEST(ImageIo, SixteenBitColorConverts) {
  test::TempDir dir("io-img");
  cv::Mat bgr(2, 1, CV_16UC3, cv::Scalar(0, 32768, 65535));
  bgr.at<cv::Vec3w>(1, 0) = cv::Vec3w(65535, 0, 13107);
  ASSERT_TRUE(cv::imwrite((dir / "c16.png").string(), bgr));
  const ColorImage c = read_color(dir / "c16.png");
  EXPECT_FLOAT_EQ(c(0, 0).x(), 1.0f);
  EXPECT_FLOAT_EQ(c(0, 0).y(), 32768.0f / 65535.0f);
  EXPECT_FLOAT_EQ(c(0, 0).z(), 0.0f);
  EXPECT_FLOAT_EQ(c(0, 1).x(), 0.2f);
  EXPECT_FLOAT_EQ(c(0, 1).z(), 1.0f);
}

TEST(ImageIo, DepthRoundTripWithinHalfAUnit) {
  test::TempDir dir("io-img");
  for (const float scale : {5000.0f, 1000.0f, 6553.5f}) {
    DepthImage d(16, 9);
    for (size_t i = 0; i < d.size(); ++i) d[i] = 0.3f + 0.0371f * float(i) / 3.0f;
    d[0] = 0.0f;
    d[1] = -1.0f;              // invalid -> 0
    d[2] = std::nanf("");      // invalid -> 0
    d[3] = 70000.0f / scale;   // does not fit uint16 -> 0
    write_depth_png(dir / "d.png", d, scale);
    const DepthImage back = read_depth(dir / "d.png", scale);
    ASSERT_TRUE(back.same_size(d));
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(back[i], 0.0f) << i;
    for (size_t i = 4; i < d.size(); ++i) EXPECT_LE(std::abs(back[i] - d[i]), 0.5f / scale + 1e-6f) << i;
    const Image<uint16_t> raw = read_depth_raw(dir / "d.png");
    EXPECT_EQ(raw[4], uint16_t(std::lround(double(d[4]) * scale)));
  }
}

TEST(ImageIo, LabelsAndMasksRoundTrip) {
  test::TempDir dir("io-img");
  LabelImage l(4, 3);
  for (size_t i = 0; i < l.size(); ++i) l[i] = uint16_t(i * 5000);
  write_labels_png(dir / "l.png", l);
  const LabelImage lb = read_labels(dir / "l.png");
  for (size_t i = 0; i < l.size(); ++i) EXPECT_EQ(lb[i], l[i]);
  MaskImage m(3, 2);
  m[1] = 1;
  m[4] = 1;
  write_mask_png(dir / "m.png", m);
  const cv::Mat stored = cv::imread((dir / "m.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(stored.type(), CV_8UC1);
  EXPECT_EQ(stored.at<uint8_t>(0, 1), 255);
  const MaskImage mb = read_mask(dir / "m.png");
  for (size_t i = 0; i < m.size(); ++i) EXPECT_EQ(mb[i], m[i]);
  // An 8-bit label file reads too.
  const LabelImage from_mask = read_labels(dir / "m.png");
  EXPECT_EQ(from_mask[1], 255);
}

TEST(ImageIo, WrongBitDepthOrChannelsIsAnError) {
  test::TempDir dir("io-img");
  write_mask_png(dir / "eight.png", MaskImage(4, 4));
  expect_error([&] { read_depth(dir / "eight.png", 5000.0f); }, {"eight.png", "8-bit", "16-bit"});
  write_color_png(dir / "rgb.png", ColorImage(4, 4, Color::Zero()));
  expect_error([&] { read_labels(dir / "rgb.png"); }, {"rgb.png", "3-channel"});
  expect_error([&] { read_depth(dir / "rgb.png", 1000.0f); }, {"rgb.png", "3-channel"});
  EXPECT_THROW(read_depth(dir / "eight.png", 0.0f), std::invalid_argument);
}

TEST(ImageIo, MissingOrGarbageFileNamesIt) {
  test::TempDir dir("io-img");
  expect_error([&] { read_color(dir / "nope.png"); }, {"not found", "nope.png"});
  std::ofstream(dir / "junk.png") << "this is not a png";
  expect_error([&] { read_color(dir / "junk.png"); }, {"cannot decode", "junk.png"});
}

TEST(ImageIo, FailedWriteLeavesNothingBehind) {
  test::TempDir dir("io-img");
  EXPECT_THROW(write_color_png(dir / "empty.png", ColorImage()), std::invalid_argument);
  EXPECT_THROW(write_depth_png(dir / "d.png", DepthImage(2, 2), -1.0f), std::invalid_argument);
  // A destination that is an existing folder: encoding succeeds, the rename fails.
  fs::create_directories(dir / "taken.png" / "x");
  EXPECT_ANY_THROW(write_color_png(dir / "taken.png", ColorImage(2, 2, Color::Zero())));
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1u);  // only taken.png/, no temporaries, no empty.png / d.png
}

}  // namespace
}  // namespace rrg::io
