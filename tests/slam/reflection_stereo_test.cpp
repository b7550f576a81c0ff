// The plane sweep behind reflective planes (core/slam/reflection_stereo.h) on an analytic scene: a
// mirror z = 2 in front of cameras looking down +z, showing a textured virtual wall at z = z_v
// behind it. Every view's colour is the wall's texture where its ray meets z = z_v, so the depth the
// sweep finds must be z_v.
#include "core/slam/reflection_stereo.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rrg {
namespace {

constexpr int kW = 160, kH = 120;
constexpr int32_t kMirror = 3;

Intrinsics camera() { return {140.0f, 140.0f, 79.5f, 59.5f, kW, kH}; }

// A smooth texture with structure in both directions (no repeats within the views' footprint).
Color texture(float x, float y) {
  return Color(0.5f + 0.4f * std::sin(7.1f * x + 2.3f * std::sin(3.7f * y)),
               0.5f + 0.4f * std::sin(5.3f * y + 1.9f * std::cos(4.1f * x)),
               0.5f + 0.3f * std::sin(3.1f * (x + y)));
}

struct View {
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  ColorImage C{kW, kH};
  Image<int32_t> I{kW, kH, 0};
};

// Camera at `centre` looking down +z; the mirror covers the pixels whose ray meets z = 2 inside
// |x| <= half_width (I = kMirror there); its colour is the virtual wall z = z_v along the ray.
View render(const Eigen::Vector3f& centre, float z_v, float half_width = 10.0f) {
  View v;
  v.T_wc.translation() = centre;
  const Intrinsics K = camera();
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Eigen::Vector3f d = K.unproject(float(x), float(y), 1.0f);
      const Eigen::Vector3f on_mirror = centre + (2.0f - centre.z()) * d;
      const Eigen::Vector3f on_wall = centre + (z_v - centre.z()) * d;
      v.C(x, y) = texture(on_wall.x(), on_wall.y());
      v.I(x, y) = std::abs(on_mirror.x()) <= half_width ? kMirror : 0;
    }
  return v;
}

const std::vector<ReflectivePlane> kPlanes = {{kMirror, Eigen::Vector4f(0, 0, 1, -2)}};  // z = 2

std::vector<StereoView> stereo_views(const std::vector<View>& views) {
  std::vector<StereoView> out;
  for (const View& v : views) out.push_back({v.T_wc, &v.C, &v.I});
  return out;
}

TEST(ReflectionStereo, FindsTheVirtualWallBehindTheMirror) {
  const float f = camera().fx, b = 0.3f;  // the widest baseline
  for (const float z_v : {3.0f, 5.0f, 7.0f}) {
    const View ref = render({0, 0, 0}, z_v);
    const std::vector<View> others = {render({b, 0, 0}, z_v), render({-0.2f, 0.1f, 0}, z_v),
                                      render({0.1f, -0.25f, 0.1f}, z_v)};
    const Image<float> D = reflection_stereo_depth(camera(), ref.T_wc, ref.C, ref.I, nullptr, kPlanes,
                                                   stereo_views(others), ReflectionStereoParams{});
    // the error as disparity in the widest view, f b |1/z − 1/z_v| pixels
    std::vector<float> err;
    for (int y = 4; y < kH - 4; ++y)
      for (int x = 4; x < kW - 4; ++x) {
        ASSERT_GT(D(x, y), 2.0f) << "pixel " << x << "," << y << ": not behind the mirror";
        err.push_back(f * b * std::abs(1.0f / D(x, y) - 1.0f / z_v));
      }
    std::sort(err.begin(), err.end());
    const float median = err[err.size() / 2], p90 = err[err.size() * 9 / 10];
    std::printf("[ stereo ] wall at %.1f m: disparity error median %.3f px, 90th percentile %.3f px\n", z_v, median, p90);
    EXPECT_LT(median, 0.2f) << z_v;
    EXPECT_LT(p90, 0.5f) << z_v;
  }
}

TEST(ReflectionStereo, LeavesPixelsNoOtherViewSeesThroughThePlaneAndHonoursTheMask) {
  const float z_v = 4.0f;
  const View ref = render({0, 0, 0}, z_v);
  // the other view's mirror is only x <= 0 on the mirror plane: rays of the reference's right half
  // reach it only through the wall (I = 0 there), so they get no depth
  View other = render({0.1f, 0, 0}, z_v);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Eigen::Vector3f on_mirror = other.T_wc.translation() + 2.0f * camera().unproject(float(x), float(y), 1.0f);
      if (on_mirror.x() > 0.0f) other.I(x, y) = 0;
    }
  MaskImage want(kW, kH, uint8_t(1));
  for (int x = 0; x < kW; ++x) want(x, 10) = 0;
  View ref_cut = ref;
  for (int x = 0; x < kW; ++x) ref_cut.I(x, 20) = 0;  // off the plane: nothing to sweep
  const std::vector<View> others = {other};
  const Image<float> D = reflection_stereo_depth(camera(), ref.T_wc, ref_cut.C, ref_cut.I, &want, kPlanes,
                                                 stereo_views(others), ReflectionStereoParams{});
  const Intrinsics K = camera();
  int found_left = 0, left = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (y == 10 || y == 20) {
        EXPECT_EQ(D(x, y), 0.0f) << x << "," << y;
        continue;
      }
      // the reference ray meets z = 2 at x_m; seen through the other's mirror only for x_m well left of 0
      const float x_m = 2.0f * K.unproject(float(x), float(y), 1.0f).x();
      if (x_m > 0.1f) EXPECT_EQ(D(x, y), 0.0f) << x << "," << y;
      if (x_m < -0.5f && x > 4 && y > 4 && y < kH - 4) {
        ++left;
        found_left += std::abs(D(x, y) - z_v) < 0.3f;
      }
    }
  ASSERT_GT(left, 100);
  EXPECT_GT(found_left, left * 9 / 10);
}

TEST(ReflectionStereo, NoUsableViewGivesNothingAndBadInputThrows) {
  const View ref = render({0, 0, 0}, 4.0f);
  // the same camera centre (baseline 0) constrains nothing
  const std::vector<View> same = {render({0, 0, 0}, 4.0f)};
  const Image<float> D = reflection_stereo_depth(camera(), ref.T_wc, ref.C, ref.I, nullptr, kPlanes, stereo_views(same),
                                                 ReflectionStereoParams{});
  for (float z : D.pixels()) ASSERT_EQ(z, 0.0f);

  const std::vector<View> others = {render({0.1f, 0, 0}, 4.0f)};
  const ColorImage small(kW / 2, kH / 2);
  EXPECT_THROW(reflection_stereo_depth(camera(), ref.T_wc, small, ref.I, nullptr, kPlanes, stereo_views(others), {}),
               std::invalid_argument);
  const std::vector<ReflectivePlane> zero = {{kMirror, Eigen::Vector4f::Zero()}};
  EXPECT_THROW(reflection_stereo_depth(camera(), ref.T_wc, ref.C, ref.I, nullptr, zero, stereo_views(others), {}),
               std::invalid_argument);
  std::vector<StereoView> missing = stereo_views(others);
  missing[0].I = nullptr;
  EXPECT_THROW(reflection_stereo_depth(camera(), ref.T_wc, ref.C, ref.I, nullptr, kPlanes, missing, {}),
               std::invalid_argument);
  ReflectionStereoParams bad;
  bad.far = bad.near;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = {};
  bad.max_hypotheses = 1;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rrg
