// Reflection attributes (paper §4.1.4, supplement "TSDF Color Variance Update" and "Global Plane
// Maintenance"): Welford statistics, reflection strength r, plane ids through the remap table.
#include "core/tsdf/tsdf_integrate.h"
#include "core/tsdf/tsdf_mesh.h"
#include "core/tsdf/tsdf_raycast.h"
#include "tests/tsdf/analytic_scene.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

namespace rrg {
namespace {

const Intrinsics kK{120.0f, 120.0f, 39.5f, 29.5f, 80, 60};
const test::Scene kPlane{{{test::Primitive::Plane, {0, 0, 1}, {0.0f, 0, 0}}}};
const Eigen::Isometry3f kPose = test::look_at({0.01f, 0.02f, 0.7f}, {0, 0, 0}, {0, 1, 0});

TsdfParams params() {
  TsdfParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  return p;
}

struct Observation {
  DeviceImage<int32_t> ids;
  DeviceImage<uint8_t> mask;
};

// Left half (x < width / 2): plane `left_id`, mask `left_mask`; right half: no plane, mask 0.
Observation half_image(int32_t left_id, uint8_t left_mask, const Device& device) {
  Image<int32_t> ids(kK.width, kK.height, 0);
  Image<uint8_t> mask(kK.width, kK.height, 0);
  for (int y = 0; y < kK.height; ++y)
    for (int x = 0; x < kK.width / 2; ++x) {
      ids(x, y) = left_id;
      mask(x, y) = left_mask;
    }
  return {DeviceImage<int32_t>::from_host(ids, device), DeviceImage<uint8_t>::from_host(mask, device)};
}

void fuse(TsdfVolume& v, const Color& c, const ReflectionObservation* refl) {
  const auto depth = DeviceImage<float>::from_host(kPlane.render_depth(kK, kPose), v.device());
  const auto color = DeviceImage<Color>::from_host(ColorImage(kK.width, kK.height, c), v.device());
  integrate(v, depth, color, kK, kPose, refl);
}

// The voxels on the plane (|z| < s/2) that every frame observed.
std::vector<Voxel> surface_voxels(const TsdfVolume& v, int weight) {
  std::vector<Voxel> out;
  for (const BlockData& b : v.read_all_blocks())
    for (int i = 0; i < kBlockVoxels; ++i)
      if (b.coord.z() * kBlockSide + (i >> 6) == 0 && b.voxels[size_t(i)].weight == weight)
        out.push_back(b.voxels[size_t(i)]);
  return out;
}

TEST(TsdfReflection, WelfordVarianceEqualsTwoPassVarianceOfIdentificationFrames) {
  const std::array<Color, 8> colors = {Color(0.1f, 0.2f, 0.3f), Color(0.9f, 0.9f, 0.9f), Color(0.5f, 0.7f, 0.2f),
                                       Color(0.0f, 0.1f, 0.0f), Color(0.8f, 0.3f, 0.6f), Color(0.4f, 0.4f, 0.4f),
                                       Color(0.3f, 0.9f, 0.6f), Color(1.0f, 0.0f, 0.5f)};
  // Identification on even frames only: x_t = (r + g + b) / 3 over those.
  double mean = 0, var = 0;
  std::vector<double> xs;
  for (size_t k = 0; k < colors.size(); k += 2) xs.push_back((colors[k].x() + colors[k].y() + colors[k].z()) / 3.0);
  for (double x : xs) mean += x / double(xs.size());
  for (double x : xs) var += (x - mean) * (x - mean) / double(xs.size());  // two-pass, population
  Color all_mean = Color::Zero();
  for (const Color& c : colors) all_mean += c / float(colors.size());

  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume v(params(), device);
    const Observation obs = half_image(2, 0, device);
    const ReflectionObservation refl{&obs.ids, &obs.mask, {}};
    for (size_t k = 0; k < colors.size(); ++k) fuse(v, colors[k], k % 2 == 0 ? &refl : nullptr);
    const auto voxels = surface_voxels(v, int(colors.size()));
    ASSERT_GT(voxels.size(), 100u);
    for (const Voxel& vox : voxels) {
      ASSERT_EQ(vox.n, 4);
      ASSERT_NEAR(vox.mu, mean, 1e-6);
      ASSERT_NEAR(voxel_variance(vox), var, 1e-6);
      ASSERT_LT((voxel_color(vox) - all_mean).norm(), 2e-4);  // c̄ over all 8 frames
    }
    // C_var from the raycast: all 8 neighbours carry the same σ², so C_var = σ² (up to ε).
    const RaycastResult r = raycast(v, kK, kPose);
    const auto cvar = r.color_variance.to_host();
    const auto color = r.colors.to_host();
    EXPECT_NEAR(cvar(kK.width / 2, kK.height / 2), var, 1e-5);
    EXPECT_LT((color(kK.width / 2, kK.height / 2) - all_mean).norm(), 2e-4);
  }
}

TEST(TsdfReflection, PlaneIdsAreRemappedAndTheMaskLandsOnItsHalf) {
  const std::vector<int32_t> remap = {0, 1, 2, 1};  // plane 3 was merged into plane 1
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    TsdfVolume v(params(), device);
    const Observation obs = half_image(3, 1, device);
    const ReflectionObservation refl{&obs.ids, &obs.mask, remap};
    fuse(v, Color(0.5f, 0.5f, 0.5f), nullptr);
    fuse(v, Color(0.5f, 0.5f, 0.5f), &refl);
    fuse(v, Color(0.5f, 0.5f, 0.5f), nullptr);
    int left = 0, right = 0;
    for (const Voxel& vox : surface_voxels(v, 3)) {
      ASSERT_TRUE(vox.plane == 0 || vox.plane == 1) << vox.plane;  // stored canonical, never 3
      left += vox.plane == 1;
      right += vox.plane == 0;
    }
    EXPECT_GT(left, 100);
    EXPECT_GT(right, 100);

    const RaycastResult r = raycast(v, kK, kPose, remap);
    const auto ids = r.plane_ids.to_host();
    const auto mask = r.reflection_mask.to_host();
    const auto raw = r.reflection.to_host();
    const int margin = 3;
    for (int y = margin; y < kK.height - margin; ++y)
      for (int x = margin; x < kK.width - margin; ++x) {
        if (x < kK.width / 2 - margin) {
          ASSERT_EQ(ids(x, y), 1) << x << "," << y;
          ASSERT_EQ(mask(x, y), 1) << x << "," << y;
          ASSERT_GT(raw(x, y), 0.999f);
        } else if (x > kK.width / 2 + margin) {
          ASSERT_EQ(ids(x, y), 0) << x << "," << y;
          ASSERT_EQ(mask(x, y), 0) << x << "," << y;
          ASSERT_LT(raw(x, y), 1e-3f);
        }
      }
    // A later merge (1 -> 5) applies at raycast time to what was fused before.
    const std::vector<int32_t> later = {0, 5};
    const auto ids5 = raycast(v, kK, kPose, later).plane_ids.to_host();
    EXPECT_EQ(ids5(margin + 2, kK.height / 2), 5);
    EXPECT_EQ(ids5(kK.width - margin - 2, kK.height / 2), 0);
    // ... and to the mesh: vertices carry 1 on the left half, 0 on the right.
    const TriangleMesh mesh = extract_mesh(v, remap);
    ASSERT_FALSE(mesh.triangles.empty());
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      const float x_img = kK.project(kPose.inverse() * mesh.vertices[i]).x();
      if (x_img < kK.width / 2 - margin && x_img > margin) ASSERT_EQ(mesh.plane_ids[i], 1);
      if (x_img > kK.width / 2 + margin && x_img < kK.width - margin) ASSERT_EQ(mesh.plane_ids[i], 0);
    }
  }
}

TEST(TsdfReflection, ReflectionStrengthIsASlidingAverageOverTheWindow) {
  // r ← r + (m − r) / min(n, W): masks 1, 0, 0 give 1, 1/2, 1/4 with W = 2 and 1, 1/2, 1/3 with W = 5.
  for (const auto& [window, expected] : {std::pair{2, 0.25f}, std::pair{5, 1.0f / 3.0f}}) {
    TsdfParams p = params();
    p.reflection_window = window;
    TsdfVolume v(p, Device::cpu());
    const Observation on = half_image(1, 1, Device::cpu()), off = half_image(1, 0, Device::cpu());
    const ReflectionObservation r_on{&on.ids, &on.mask, {}}, r_off{&off.ids, &off.mask, {}};
    for (const ReflectionObservation* r : {&r_on, &r_off, &r_off}) fuse(v, Color(0.5f, 0.5f, 0.5f), r);
    int checked = 0;
    for (const Voxel& vox : surface_voxels(v, 3))
      if (vox.plane == 1) {
        ASSERT_NEAR(voxel_codec::decode_unit(vox.r), expected, 1e-4) << "W = " << window;
        ++checked;
      }
    EXPECT_GT(checked, 100);
  }
}

// Auto-exposure (core/planes/exposure_gain.h): a matte grey wall seen through gains 0.7 .. 1.4 has
// the variance of the gains in its Welford statistic; fused with each frame's gain it has none,
// while colour fusion (c̄) still averages the frames as they are.
TEST(TsdfReflection, ExposureGainTakesAutoExposureOutOfTheVariance) {
  const std::array<float, 5> gains = {0.7f, 1.0f, 1.4f, 0.85f, 1.2f};
  const Color grey(0.6f, 0.5f, 0.4f);  // x = 0.5
  double mean = 0, var = 0, c_mean = 0;
  for (float g : gains) mean += 0.5 * g / double(gains.size());
  for (float g : gains) var += (0.5 * g - mean) * (0.5 * g - mean) / double(gains.size());
  for (float g : gains) c_mean += 0.6 * g / double(gains.size());
  ASSERT_GT(var, 0.01);  // above δ_v without the gains
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    for (const bool compensate : {false, true}) {
      TsdfVolume v(params(), device);
      const Observation obs = half_image(2, 0, device);
      for (float g : gains) {
        const ReflectionObservation refl{&obs.ids, &obs.mask, {}, compensate ? g : 1.0f};
        fuse(v, g * grey, &refl);
      }
      const auto voxels = surface_voxels(v, int(gains.size()));
      ASSERT_GT(voxels.size(), 100u);
      for (const Voxel& vox : voxels) {
        ASSERT_NEAR(vox.mu, compensate ? 0.5 : mean, 1e-5);
        ASSERT_NEAR(voxel_variance(vox), compensate ? 0.0 : var, 1e-6);
        ASSERT_NEAR(voxel_color(vox).x(), c_mean, 2e-3);  // c̄: the frames as they are
      }
    }
  }
}

TEST(TsdfReflection, RejectsAnIncompleteObservation) {
  TsdfVolume v(params(), Device::cpu());
  const Observation obs = half_image(1, 1, Device::cpu());
  const ReflectionObservation refl{&obs.ids, nullptr, {}};
  EXPECT_THROW(fuse(v, Color(0.5f, 0.5f, 0.5f), &refl), std::invalid_argument);
  const Observation full = half_image(1, 1, Device::cpu());
  for (const float gain : {0.0f, -1.0f, std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()}) {
    const ReflectionObservation bad{&full.ids, &full.mask, {}, gain};
    EXPECT_THROW(fuse(v, Color(0.5f, 0.5f, 0.5f), &bad), std::invalid_argument) << gain;
  }
}

}  // namespace
}  // namespace rrg
