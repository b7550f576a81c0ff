// Densification (candidate rules, back-projection, GPS-SLAM initialisation, reflection samples along
// the ray past the plane, deterministic sampling) and pruning thresholds (with CPU/CUDA parity).
#include "core/gaussians/densify.h"
#include "core/gaussians/prune.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rrg {
namespace {

constexpr float kC0 = 0.28209479177387814f;

struct WallView {
  Intrinsics K{40, 40, 15.5f, 11.5f, 32, 24};
  ColorImage C_gt{32, 24, Color(0.8f, 0.4f, 0.2f)};
  DepthImage D_gt{32, 24, 2.0f};
  ColorImage C{32, 24, Color(0.8f, 0.4f, 0.2f)};  // perfect except where changed
  ColorImage C_b{32, 24, Color(0.5f, 0.3f, 0.2f)};
  Image<float> W_b{32, 24, 0.0f}, W_r{32, 24, 0.0f}, C_var{32, 24, 0.02f};
  MaskImage R{32, 24, 1};
  Image<int32_t> I{32, 24, 4};
  DensifyView view() const {
    DensifyView v;
    v.K = K;
    v.C_gt = &C_gt;
    v.D_gt = &D_gt;
    v.C = &C;
    v.C_b = &C_b;
    v.W_b = &W_b;
    v.W_r = &W_r;
    v.R = &R;
    v.C_var = &C_var;
    v.I = &I;
    return v;
  }
};

TEST(Densify, BaseCandidatesFollowErrorAndWeightRules) {
  WallView w;
  for (int x = 0; x < 16; ++x)
    for (int y = 0; y < 24; ++y) w.C(x, y) = Color(0.8f, 0.4f, 0.0f);  // error 0.2/3 = 0.067 > 0.05
  for (int y = 0; y < 24; ++y) w.C(16, y) = Color(0.8f, 0.4f, 0.1f);  // error 0.033: not a candidate
  for (int y = 0; y < 12; ++y) w.W_b(3, y) = 3.0f;                    // covered: not a candidate
  w.D_gt(5, 5) = 0.0f;                                                 // no depth: not a candidate
  DensifyParams p;
  p.sample_ratio = 1.0f;
  const GaussianHost g = densify_base(w.view(), p, 1, 7);
  EXPECT_EQ(g.size(), size_t(16 * 24 - 12 - 1));
  for (size_t i = 0; i < g.size(); ++i) {
    EXPECT_NEAR(g.means[i].z(), 2.0f, 1e-5f);  // on the wall (identity pose)
    EXPECT_LT(g.means[i].x(), 0.0f);           // left half of the image
    EXPECT_EQ(g.plane_ids[i], 0);
    EXPECT_NEAR(1.0f / (1.0f + std::exp(-g.logit_opacities[i])), 0.5f, 1e-6f);
    EXPECT_NEAR(g.sh[i * 4].x() * kC0 + 0.5f, 0.8f, 1e-6f);  // SH DC from the pixel colour
    EXPECT_EQ(g.sh[i * 4 + 1], Eigen::Vector3f::Zero());
    // pixel footprint 2 m / 40 px = 5 cm > 1 cm cap: tangential scale 1 cm, normal axis 1 mm
    EXPECT_NEAR(std::exp(g.log_scales[i].x()), 0.01f, 1e-6f);
    EXPECT_NEAR(std::exp(g.log_scales[i].z()), 0.001f, 1e-7f);
    // the flat axis (local z) is the wall normal R e_z = ±(0, 0, 1) inside the image; on the
    // border and next to the depth hole (no central difference) it is the reversed viewing ray
    const Eigen::Quaternionf q(g.quats[i][0], g.quats[i][1], g.quats[i][2], g.quats[i][3]);
    const Eigen::Vector2f px = w.K.project(g.means[i]);
    const bool border = px.x() < 0.5f || px.y() < 0.5f || px.y() > 22.5f ||
                        std::abs(px.x() - 5.0f) + std::abs(px.y() - 5.0f) < 1.5f;  // next to the hole
    const Eigen::Vector3f expected = border ? Eigen::Vector3f(-g.means[i].normalized()) : Eigen::Vector3f(0, 0, -1);
    EXPECT_NEAR(std::abs((q * Eigen::Vector3f::UnitZ()).dot(expected)), 1.0f, 1e-5f);
  }
}

// base_leaves_reflections: pixels the reflection set may take (R = 1 on a given reflective plane,
// and C_var > δ_v with the variance gate) get no base Gaussian; every other candidate still does;
// off = the plain rule.
TEST(Densify, BaseLeavesReflectionCandidatesWhenAsked) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color(0.8f, 0.4f, 0.0f);       // every pixel a base candidate
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 8; ++x) w.R(x, y) = 0;                     // columns 0-7: not reflective
  for (int y = 0; y < 24; ++y) w.C_var(8, y) = 0.005f;             // column 8: steady colour
  for (int y = 0; y < 24; ++y) w.I(9, y) = 5;                      // column 9: another plane
  const std::vector<ReflectivePlane> planes{{4, Eigen::Vector4f(0, 0, -1, 2)}};
  DensifyParams p;
  p.sample_ratio = 1.0f;
  EXPECT_EQ(densify_base(w.view(), p, 0, 3, planes).size(), size_t(32 * 24));  // off by default
  p.base_leaves_reflections = true;
  EXPECT_EQ(densify_base(w.view(), p, 0, 3).size(), size_t(32 * 24));          // no planes given
  const GaussianHost g = densify_base(w.view(), p, 0, 3, planes);
  EXPECT_EQ(g.size(), size_t(9 * 24));  // columns 0-7 and 9 (column 8 is the reflection set's too)
  for (const auto& m : g.means) EXPECT_TRUE(std::abs(w.K.project(m).x() - 8.0f) > 0.5f && w.K.project(m).x() < 9.5f);
  p.reflection_variance_gate = true;     // with the paper's gate, column 8 is not
  const GaussianHost gated = densify_base(w.view(), p, 0, 3, planes);
  EXPECT_EQ(gated.size(), size_t(10 * 24));  // columns 0-9
  for (const auto& m : gated.means) EXPECT_LT(w.K.project(m).x(), 9.5f);
}

TEST(Densify, ScaleFromThreeNearestNewPoints) {
  // Close wall: 0.2 m at f = 40 -> 5 mm between pixels; 3 nearest at 5, 5, 5 mm.
  WallView w;
  for (auto& d : w.D_gt.pixels()) d = 0.2f;
  for (auto& c : w.C.pixels()) c = Color::Zero();
  DensifyParams p;
  p.sample_ratio = 1.0f;
  const GaussianHost g = densify_base(w.view(), p, 0, 1);
  // an interior pixel: neighbours at 5 mm (x and y)
  const size_t i = size_t(10 * 32 + 10);
  EXPECT_NEAR(std::exp(g.log_scales[i].x()), 0.005f, 1e-5f);
}

TEST(Densify, SamplingIsDeterministicAndRespectsTheRatio) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color::Zero();
  DensifyParams p;
  p.sample_ratio = 0.3f;
  const GaussianHost a = densify_base(w.view(), p, 0, 42), b = densify_base(w.view(), p, 0, 42);
  const GaussianHost c = densify_base(w.view(), p, 0, 43);
  EXPECT_EQ(a.means, b.means);
  EXPECT_NE(a.means, c.means);
  EXPECT_NEAR(double(a.size()) / (32 * 24), 0.3, 0.06);
}

TEST(Densify, ReflectionSamplesLiePastThePlaneAlongTheRay) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color::Zero();   // error 0.47 everywhere
  for (int x = 0; x < 32; ++x) w.C_var(x, 0) = 0.005f;  // row 0: variance below δ_v
  for (int x = 0; x < 32; ++x) w.R(x, 1) = 0;           // row 1: not reflective
  for (int x = 0; x < 32; ++x) w.W_r(x, 2) = 0.5f;      // row 2: covered
  for (int x = 0; x < 32; ++x) w.I(x, 3) = 9;           // row 3: plane not in L_ref
  const std::vector<ReflectivePlane> planes = {{4, Eigen::Vector4f(0, 0, -2, 4)}};  // z = 2 (unnormalised)
  DensifyParams p;
  p.sample_ratio = 1.0f;
  p.reflection_residual_color = false;  // the paper's colour, C_gt (the residual is checked below)
  // Row 0 is a candidate by default (R = 1 on an accepted plane suffices), not with the paper's
  // per-pixel variance gate.
  EXPECT_EQ(densify_reflection(w.view(), planes, p, 0, 3).size(), size_t(21 * 32 * 10));
  p.reflection_variance_gate = true;
  const GaussianHost g = densify_reflection(w.view(), planes, p, 0, 3);
  ASSERT_EQ(g.size(), size_t(20 * 32 * 10));
  for (size_t s = 0; s < g.size(); s += 10) EXPECT_GT(w.K.project(g.means[s]).y(), 0.5f);  // not row 0
  for (size_t s = 0; s < g.size(); s += 10) {
    const Eigen::Vector3f dir = g.means[s].normalized();
    const Eigen::Vector3f hit = dir * (2.0f / dir.z());
    for (int j = 0; j < 10; ++j) {
      const Eigen::Vector3f p_j = g.means[s + size_t(j)];
      EXPECT_NEAR((p_j - hit).norm(), 2.0f + 6.0f * float(j) / 9.0f, 1e-4f);
      EXPECT_NEAR(p_j.normalized().dot(dir), 1.0f, 1e-6f);  // on the viewing ray
      EXPECT_EQ(g.plane_ids[s + size_t(j)], 4);
    }
    // colour = the pixel colour (0.8, 0.4, 0.2)
    EXPECT_NEAR(g.sh[s].x() * kC0 + 0.5f, 0.8f, 1e-6f);
    EXPECT_NEAR(g.sh[s].z() * kC0 + 0.5f, 0.2f, 1e-6f);
  }
  // the default, the residual: C_gt − C_b = (0.3, 0.1, 0)
  p.reflection_residual_color = true;
  const GaussianHost r = densify_reflection(w.view(), planes, p, 0, 3);
  EXPECT_NEAR(r.sh[0].x() * kC0 + 0.5f, 0.3f, 1e-6f);
  EXPECT_NEAR(r.sh[0].z() * kC0 + 0.5f, 0.0f, 1e-6f);
}

// reflection_candidates() marks exactly the pixels densify_reflection() samples with the same
// arguments (each makes the S ray samples when no virtual depth is given).
TEST(Densify, ReflectionCandidatesAreThePixelsDensificationSamples) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color::Zero();
  for (int x = 0; x < 32; ++x) w.R(x, 1) = 0;       // row 1: not reflective
  for (int x = 0; x < 32; ++x) w.W_r(x, 2) = 0.5f;  // row 2: covered
  for (int x = 0; x < 32; ++x) w.I(x, 3) = 9;       // row 3: plane not in L_ref
  for (int y = 0; y < 24; ++y) w.C(5, y) = w.C_gt(5, y);  // column 5: no error
  const std::vector<ReflectivePlane> planes = {{4, Eigen::Vector4f(0, 0, -2, 4)}};
  DensifyParams p;
  p.sample_ratio = 0.4f;
  for (const uint64_t seed : {3ull, 4ull}) {
    const MaskImage m = reflection_candidates(w.view(), planes, p, seed);
    const GaussianHost g = densify_reflection(w.view(), planes, p, 0, seed);
    std::vector<int> made(32 * 24, 0);
    for (size_t s = 0; s < g.size(); s += 10) {
      const Eigen::Vector2f q = w.K.project(g.means[s]);
      ++made[size_t(std::lround(q.y())) * 32 + size_t(std::lround(q.x()))];
    }
    int64_t marked = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 32; ++x) {
        EXPECT_EQ(int(m(x, y)), made[size_t(y) * 32 + size_t(x)]) << x << "," << y << " seed " << seed;
        if (y >= 1 && y <= 3) EXPECT_EQ(m(x, y), 0) << x << "," << y;
        if (x == 5) EXPECT_EQ(m(x, y), 0) << x << "," << y;
        marked += m(x, y);
      }
    EXPECT_EQ(size_t(marked) * 10, g.size());
    EXPECT_NEAR(double(marked) / (20 * 31), 0.4, 0.08);
  }
}

// The opacity of the samples along a reflection ray: given, or derived so that the S samples
// together are as opaque as one new Gaussian (1 − (1 − 0.5)^(1/10) = 0.0670 for S = 10).
TEST(Densify, ReflectionSampleOpacityGivenOrDerived) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color::Zero();
  const std::vector<ReflectivePlane> planes = {{4, Eigen::Vector4f(0, 0, -2, 4)}};
  const auto opacity = [](float logit) { return 1.0f / (1.0f + std::exp(-logit)); };
  DensifyParams p;
  p.sample_ratio = 1.0f;
  for (const float given : {0.5f, 0.2f}) {
    p.reflection_sample_opacity = given;
    const GaussianHost g = densify_reflection(w.view(), planes, p, 0, 3);
    ASSERT_GT(g.size(), 0u);
    for (float l : g.logit_opacities) ASSERT_NEAR(opacity(l), given, 1e-6f);
  }
  p.reflection_sample_opacity = 0.0f;
  EXPECT_EQ(DensifyParams{}.reflection_sample_opacity, 0.0f);  // derived is the default
  EXPECT_NEAR(p.reflection_sample_alpha(), 0.066967f, 1e-5f);
  const GaussianHost g = densify_reflection(w.view(), planes, p, 0, 3);
  ASSERT_GT(g.size(), 0u);
  float transmitted = 1.0f;  // through the ten samples of one ray
  for (int j = 0; j < 10; ++j) transmitted *= 1.0f - opacity(g.logit_opacities[size_t(j)]);
  EXPECT_NEAR(1.0f - transmitted, p.init_opacity, 1e-5f);
  p.reflection_samples = 4;
  EXPECT_NEAR(1.0f - std::pow(1.0f - p.reflection_sample_alpha(), 4.0f), p.init_opacity, 1e-6f);
  for (const float bad : {-0.1f, 1.0f}) {
    p.reflection_sample_opacity = bad;
    EXPECT_THROW(p.validate(), std::invalid_argument) << bad;
  }
}

// With the mirrored-surface option a pixel whose virtual view meets geometry behind the plane gets
// one Gaussian there, with a new Gaussian's opacity; the other pixels keep the S ray samples with
// the sample opacity. init_gaussians takes one opacity per point and rejects one outside (0, 1).
// The plane sweep's depths (reflection_stereo_depth) take the same path.
TEST(Densify, MirroredSurfaceGaussiansTakeTheInitialOpacity) {
  WallView w;
  for (auto& c : w.C.pixels()) c = Color::Zero();
  const std::vector<ReflectivePlane> planes = {{4, Eigen::Vector4f(0, 0, -2, 4)}};  // z = 2
  Image<float> virtual_depth(32, 24, 0.0f);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 16; ++x) virtual_depth(x, y) = 3.0f;  // left half: a surface 1 m behind the plane
  DensifyParams p;
  p.sample_ratio = 1.0f;
  p.reflection_stereo_depth = false;  // on by default
  DensifyView v = w.view();
  v.virtual_depth = &virtual_depth;
  // neither option: the depths are not read
  EXPECT_EQ(densify_reflection(v, planes, p, 0, 3).size(), size_t(32 * 24 * 10));
  p.reflection_stereo_depth = true;
  const GaussianHost swept = densify_reflection(v, planes, p, 0, 3);
  p.reflection_stereo_depth = false;
  p.reflection_mirrored_depth = true;
  const GaussianHost g = densify_reflection(v, planes, p, 0, 3);
  ASSERT_EQ(swept.size(), g.size());
  for (size_t i = 0; i < g.size(); ++i) ASSERT_EQ(swept.means[i], g.means[i]) << i;
  ASSERT_EQ(g.size(), size_t(16 * 24 * 1 + 16 * 24 * 10));
  const auto opacity = [](float logit) { return 1.0f / (1.0f + std::exp(-logit)); };
  size_t at_surface = 0, on_rays = 0;
  for (size_t i = 0; i < g.size(); ++i) {
    if (std::abs(g.means[i].z() - 3.0f) < 1e-4f) {
      EXPECT_NEAR(opacity(g.logit_opacities[i]), p.init_opacity, 1e-6f);
      ++at_surface;
    } else {
      EXPECT_NEAR(opacity(g.logit_opacities[i]), p.reflection_sample_alpha(), 1e-6f);
      ++on_rays;
    }
  }
  EXPECT_EQ(at_surface, size_t(16 * 24));
  EXPECT_EQ(on_rays, size_t(16 * 24 * 10));

  const std::vector<Eigen::Vector3f> pts = {Eigen::Vector3f(0, 0, 1)}, nrm = {Eigen::Vector3f::UnitZ()};
  const std::vector<Color> col = {Color::Zero()};
  const std::vector<int32_t> ids = {0};
  for (const float bad : {0.0f, 1.0f, -0.5f, NAN})
    EXPECT_THROW(init_gaussians(pts, nrm, col, ids, std::vector<float>{bad}, p, 0.001f, 0.01f, 0), std::invalid_argument)
        << bad;
  EXPECT_THROW(init_gaussians(pts, nrm, col, ids, std::vector<float>{}, p, 0.001f, 0.01f, 0), std::invalid_argument);
  EXPECT_NEAR(opacity(init_gaussians(pts, nrm, col, ids, std::vector<float>{0.3f}, p, 0.001f, 0.01f, 0).logit_opacities[0]),
              0.3f, 1e-6f);
}

TEST(Densify, RejectsMissingOrMisSizedImages) {
  WallView w;
  DensifyView v = w.view();
  v.W_b = nullptr;
  EXPECT_THROW(densify_base(v, {}, 0, 0), std::invalid_argument);
  const Image<float> small(4, 4);
  v = w.view();
  v.W_b = &small;
  EXPECT_THROW(densify_base(v, {}, 0, 0), std::invalid_argument);
  DensifyParams p;
  p.sample_ratio = 2.0f;
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

TEST(Prune, OpacityAndScaleThresholdsOnEveryDevice) {
  GaussianHost g(0);
  g.resize(6);
  const float logit_ok = 0.0f, logit_low = std::log(0.004f / 0.996f);
  for (size_t i = 0; i < 6; ++i) {
    g.logit_opacities[i] = logit_ok;
    g.log_scales[i] = Eigen::Vector3f(std::log(0.01f), std::log(0.01f), std::log(0.001f));  // flat: kept
  }
  g.logit_opacities[1] = logit_low;                                          // opacity 0.004 < 0.005
  g.log_scales[2] = Eigen::Vector3f::Constant(std::log(0.002f));             // largest axis 2 mm < 3 mm
  g.log_scales[3] = Eigen::Vector3f(std::log(0.15f), -5.0f, -5.0f);          // 15 cm > 10 cm (base)
  g.means[4] = Eigen::Vector3f(NAN, 0, 0);                                   // not finite
  const auto keep_base = test::expect_device_parity<int>(
      [&](const Device& dev) {
        const auto m = prune_mask(GaussianSet::from_host(g, dev), PruneParams::base());
        return std::vector<int>(m.begin(), m.end());
      },
      0);
  EXPECT_EQ(keep_base, (std::vector<int>{1, 0, 0, 0, 0, 1}));
  // reflection thresholds: 15 cm < 20 cm kept; 2 mm < 5 mm pruned
  const auto keep_refl = prune_mask(GaussianSet::from_host(g, Device::cpu()), PruneParams::reflection());
  EXPECT_EQ(std::vector<int>(keep_refl.begin(), keep_refl.end()), (std::vector<int>{1, 0, 0, 1, 0, 1}));
  PruneParams bad;
  bad.max_scale = 0.001f;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace rrg
