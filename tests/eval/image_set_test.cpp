// Matching image folders / lists and scoring them from files (through core/io image files).
#include "core/eval/image_set.h"
#include "core/io/image_io.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace rrg::eval {
namespace {
namespace fs = std::filesystem;

// Colours that are exact in 8 bits (k/255), so the PNG round trip changes nothing.
ColorImage flat(int k, int w = 16, int h = 12) { return ColorImage(w, h, Color::Constant(float(k) / 255.0f)); }

void write_text(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ImageSet, FoldersMatchByStemSortedAndIgnoreOtherFiles) {
  rrg::test::TempDir dir("eval-imgset");
  for (const char* n : {"c", "a", "b"}) {
    io::write_color_png(dir / ("est/" + std::string(n) + ".png"), flat(10));
    io::write_color_png(dir / ("ref/" + std::string(n) + ".png"), flat(20));
  }
  write_text(dir / "est/notes.txt", "not an image");
  const auto pairs = match_images(dir / "est", dir / "ref");
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].name, "a");
  EXPECT_EQ(pairs[2].name, "c");
  EXPECT_EQ(pairs[1].est, dir / "est/b.png");
  EXPECT_EQ(pairs[1].ref, dir / "ref/b.png");
  EXPECT_FALSE(pairs[0].mask);
}

TEST(ImageSet, FolderMismatchNamesTheFilesOnEachSide) {
  rrg::test::TempDir dir("eval-imgset");
  io::write_color_png(dir / "est/a.png", flat(1));
  io::write_color_png(dir / "est/extra_est.png", flat(1));
  io::write_color_png(dir / "ref/a.png", flat(1));
  io::write_color_png(dir / "ref/extra_ref.png", flat(1));
  const std::string msg = error_of([&] { match_images(dir / "est", dir / "ref"); });
  EXPECT_NE(msg.find("extra_est.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("extra_ref.png"), std::string::npos) << msg;

  fs::create_directories(dir / "empty");
  EXPECT_NE(error_of([&] { match_images(dir / "empty", dir / "ref"); }).find("no image files"), std::string::npos);
  EXPECT_NE(error_of([&] { match_images(dir / "missing", dir / "ref"); }).find("missing"), std::string::npos);
}

TEST(ImageSet, ListsMatchByOrderWithPathsRelativeToTheList) {
  rrg::test::TempDir dir("eval-imgset");
  io::write_color_png(dir / "seq/rgb/1.png", flat(1));
  io::write_color_png(dir / "seq/rgb/2.png", flat(2));
  io::write_color_png(dir / "render/x.png", flat(1));
  io::write_color_png(dir / "render/y.png", flat(2));
  write_text(dir / "seq/rgb.txt", "# color images\n# timestamp filename\n1305031102.175304 rgb/1.png\n\nrgb/2.png\n");
  const auto pairs = match_images(dir / "render", dir / "seq/rgb.txt");
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].est, dir / "render/x.png");
  EXPECT_EQ(pairs[0].ref, dir / "seq/rgb/1.png");
  EXPECT_EQ(pairs[1].ref, dir / "seq/rgb/2.png");

  write_text(dir / "seq/short.txt", "rgb/1.png\n");
  const std::string msg = error_of([&] { match_images(dir / "render", dir / "seq/short.txt"); });
  EXPECT_NE(msg.find("has 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("has 1"), std::string::npos) << msg;

  write_text(dir / "seq/bad.txt", "rgb/1.png\nrgb/nope.png\n");
  EXPECT_NE(error_of([&] { list_images(dir / "seq/bad.txt"); }).find("bad.txt:2"), std::string::npos);
  write_text(dir / "seq/junk.txt", "a b c\n");
  EXPECT_NE(error_of([&] { list_images(dir / "seq/junk.txt"); }).find("junk.txt:1"), std::string::npos);
}

TEST(ImageSet, ScoresFilesWithAndWithoutMasks) {
  // 8-bit values 51 vs 77: MSE = (26/255)², PSNR = −20·log10(26/255) = 19.8303 dB.
  rrg::test::TempDir dir("eval-imgset");
  io::write_color_png(dir / "est/0.png", flat(51));
  io::write_color_png(dir / "ref/0.png", flat(77));
  ColorImage half = flat(40);
  MaskImage left(16, 12, 0);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 8; ++x) left(x, y) = 1;
  for (int y = 0; y < 12; ++y)
    for (int x = 8; x < 16; ++x) half(x, y) = Color::Constant(200.0f / 255.0f);  // differs only outside the mask
  io::write_color_png(dir / "est/1.png", half);
  io::write_color_png(dir / "ref/1.png", flat(40));
  io::write_mask_png(dir / "mask/0.png", MaskImage(16, 12, 1));
  io::write_mask_png(dir / "mask/1.png", left);

  const auto plain = evaluate_image_pairs(match_images(dir / "est", dir / "ref"));
  ASSERT_EQ(plain.images.size(), 2u);
  EXPECT_NEAR(plain.images[0].psnr_db, -20.0 * std::log10(26.0 / 255.0), 1e-4);
  EXPECT_FALSE(plain.masked);
  EXPECT_LT(plain.images[1].psnr_db, 10.0);

  size_t calls = 0;
  const auto masked = evaluate_image_pairs(match_images(dir / "est", dir / "ref", dir / "mask"),
                                           [&](size_t done, size_t total) { EXPECT_EQ(total, 2u); calls = done; });
  EXPECT_EQ(calls, 2u);
  EXPECT_TRUE(masked.masked);
  EXPECT_TRUE(std::isinf(masked.images[1].psnr_db));
  EXPECT_TRUE(std::isinf(masked.mean_psnr_db));
  EXPECT_NEAR(masked.images[0].psnr_db, plain.images[0].psnr_db, 1e-9);
  EXPECT_LT(masked.images[1].ssim, 1.0);  // the SSIM window still sees the unmasked half near x = 8
  EXPECT_GT(masked.images[1].ssim, plain.images[1].ssim);

  io::write_color_png(dir / "big/0.png", flat(1, 20, 12));
  io::write_color_png(dir / "big/1.png", flat(1, 20, 12));
  const std::string msg = error_of([&] { evaluate_image_pairs(match_images(dir / "big", dir / "ref")); });
  EXPECT_NE(msg.find("big/0.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("ref/0.png"), std::string::npos) << msg;
}

}  // namespace
}  // namespace rrg::eval
