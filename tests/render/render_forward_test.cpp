// Forward passes: hand-computed known answers, the plane test, the depth cull, the raycast-miss rule,
// early termination and depth order, the ablation variants, the tiled pipeline against the
// brute-force double reference, device parity and input errors.
#include "core/render/renderer.h"
#include "core/render/sh_device.h"
#include "tests/render/render_scene.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace rrg::test {
namespace {

constexpr double kC0 = 0.28209479177387814;  // SH basis constant Y_0^0

struct HostOut {
  ColorImage C, C_b, C_g, C_r;
  DepthImage D_b, D_g, W_g, W_r;
};

HostOut render_host(const RenderCamera& cam, const GaussianHost& base, const GaussianHost& refl, const HostRaycast& in,
                    const RenderParams& p, const Device& device) {
  const auto b = GaussianSet::from_host(base, device);
  const auto r = GaussianSet::from_host(refl, device);
  const auto rc = to_device(in, device);
  Renderer renderer(device, p);
  RenderOutputs out;
  renderer.render(cam, b, r, rc, out);
  return {out.C.to_host(),   out.C_b.to_host(), out.C_g.to_host(), out.C_r.to_host(),
          out.D_b.to_host(), out.D_g.to_host(), out.W_g.to_host(), out.W_r.to_host()};
}

// 64x48 identity camera, f = 100, principal point on pixel (32, 24).
RenderCamera camera64() { return {{100.f, 100.f, 32.f, 24.f, 64, 48}, Eigen::Isometry3f::Identity()}; }

HostRaycast uniform_raycast(int w, int h, const Color& C_t, float D_t, int32_t I, float R) {
  return {ColorImage(w, h, C_t), DepthImage(w, h, D_t), Image<int32_t>(w, h, I), Image<float>(w, h, R)};
}

// One isotropic Gaussian at (x, y, z) of scale s, logit opacity l, colour c (SH degree 0), plane id.
GaussianHost one_gaussian(const Eigen::Vector3f& p, float s, float logit, const Color& c, int32_t plane = 0) {
  GaussianHost g(0);
  g.resize(1);
  g.means[0] = p;
  g.log_scales[0] = Eigen::Vector3f::Constant(std::log(s));
  g.logit_opacities[0] = logit;
  g.sh[0] = ((c.array() - 0.5f) / float(kC0)).matrix();
  g.plane_ids[0] = plane;
  return g;
}

TEST(RenderForward, OneGaussianMatchesTheAnalyticFootprint) {
  // s = 0.04 m at z = 2 m, f = 100: pixel std 2 px, Sigma' = (4 + 0.3) I; sigma = sigmoid(0) = 0.5.
  const GaussianHost g = one_gaussian({0, 0, 2}, 0.04f, 0.0f, {0.8f, 0.4f, 0.2f}, 1);
  const HostRaycast in = uniform_raycast(64, 48, {0.2f, 0.2f, 0.2f}, 3.0f, 1, 1.0f);
  const HostOut base_only = render_host(camera64(), g, GaussianHost(0), in, {}, Device::cpu());
  // centre pixel: alpha = 0.5; C_b = (0.2 + 0.5 c) / 1.5, D_b = (3 + 0.5 * 2) / 1.5
  EXPECT_NEAR(base_only.C_b(32, 24).x(), 0.4, 1e-6);
  EXPECT_NEAR(base_only.C_b(32, 24).y(), 0.2 / 0.75, 1e-6);
  EXPECT_NEAR(base_only.C_b(32, 24).z(), 0.2, 1e-6);
  EXPECT_NEAR(base_only.D_b(32, 24), 4.0 / 1.5, 1e-6);
  EXPECT_NEAR(base_only.W_g(32, 24), 0.5, 1e-7);
  // two pixels right, one down: alpha = 0.5 exp(-(4 + 1) / (2 * 4.3))
  const double a = 0.5 * std::exp(-5.0 / 8.6);
  EXPECT_NEAR(base_only.W_g(34, 25), a, 1e-7);
  EXPECT_NEAR(base_only.C_g(34, 25).x(), a * 0.8, 1e-6);
  EXPECT_NEAR(base_only.D_g(34, 25), a * 2.0, 1e-6);
  EXPECT_NEAR(base_only.D_b(34, 25), (3.0 + 2.0 * a) / (1.0 + a), 1e-6);
  // far away: nothing but the TSDF
  EXPECT_EQ(base_only.W_g(5, 5), 0.0f);
  EXPECT_EQ(base_only.C_b(5, 5), Color(0.2f, 0.2f, 0.2f));
  EXPECT_EQ(base_only.D_b(5, 5), 3.0f);
  // the same Gaussian as a reflection Gaussian of plane 1: C_r = alpha c, C = C_b + R C_r
  const HostOut refl_only = render_host(camera64(), GaussianHost(0), g, in, {}, Device::cpu());
  EXPECT_NEAR(refl_only.C_r(32, 24).x(), 0.4, 1e-6);
  EXPECT_NEAR(refl_only.W_r(34, 25), a, 1e-7);
  EXPECT_NEAR(refl_only.C(32, 24).x(), 0.2 + 0.4, 1e-6);
  EXPECT_NEAR(refl_only.C(34, 25).z(), 0.2 + a * 0.2, 1e-6);
}

TEST(RenderForward, ReflectionGaussianNeverShowsOnAnotherPlane) {
  // Every reflection Gaussian belongs to plane 1; the image holds planes 1, 2 and no plane.
  const GaussianHost refl = random_gaussians(200, 1, 2.0f, 5.0f, 100.f, {1}, 3);
  HostRaycast in = uniform_raycast(64, 48, {0, 0, 0}, 2.0f, 1, 1.0f);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) in.I(x, y) = x < 20 ? 1 : (x < 40 ? 2 : 0);
  RenderParams p;
  const HostOut out = render_host(camera64(), GaussianHost(0), refl, in, p, Device::cpu());
  double on_plane = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (x < 20) {
        on_plane += out.W_r(x, y);
      } else {
        ASSERT_EQ(out.W_r(x, y), 0.0f) << x << "," << y;
        ASSERT_TRUE(out.C_r(x, y).isZero()) << x << "," << y;
      }
    }
  EXPECT_GT(on_plane, 20.0);  // they do show on their own plane
  // without plane grouping the same Gaussians cover the other planes too
  p.variant = ReflectionVariant::NoPlaneGrouping;
  const HostOut vanilla = render_host(camera64(), GaussianHost(0), refl, in, p, Device::cpu());
  double off_plane = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 20; x < 64; ++x) off_plane += vanilla.W_r(x, y);
  EXPECT_GT(off_plane, 20.0);
}

TEST(RenderForward, DepthCullRemovesOccludedBaseGaussians) {
  const GaussianHost g = one_gaussian({0, 0, 3}, 0.06f, 2.0f, {1, 0, 0});
  const Color C_t(0.1f, 0.5f, 0.9f);
  RenderParams p;  // eps = 0.02
  // surface at 2 m in front of the Gaussian at 3 m: culled, C_b = C_t exactly
  HostOut out = render_host(camera64(), g, GaussianHost(0), uniform_raycast(64, 48, C_t, 2.0f, 0, 0), p, Device::cpu());
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      ASSERT_EQ(out.W_g(x, y), 0.0f);
      ASSERT_EQ(out.C_b(x, y), C_t);
    }
  // 2.97 + eps = 2.99 < 3: still culled; 2.99 + eps = 3.01 > 3: visible
  out = render_host(camera64(), g, GaussianHost(0), uniform_raycast(64, 48, C_t, 2.97f, 0, 0), p, Device::cpu());
  EXPECT_EQ(out.W_g(32, 24), 0.0f);
  out = render_host(camera64(), g, GaussianHost(0), uniform_raycast(64, 48, C_t, 2.99f, 0, 0), p, Device::cpu());
  EXPECT_GT(out.W_g(32, 24), 0.8f);
  EXPECT_GT(out.C_b(32, 24).x(), C_t.x());
}

TEST(RenderForward, RaycastMissUsesTheGaussiansAlone) {
  // D_t = 0: no cull, no TSDF term, C_b = C_g / max(1, W_g), D_b = D_g / max(1, W_g).
  GaussianHost g = one_gaussian({0, 0, 3}, 0.06f, 0.0f, {1, 0.5f, 0});
  const HostRaycast in = uniform_raycast(64, 48, {0.7f, 0.7f, 0.7f}, 0.0f, 0, 0);
  HostOut out = render_host(camera64(), g, GaussianHost(0), in, {}, Device::cpu());
  EXPECT_NEAR(out.W_g(32, 24), 0.5, 1e-7);
  EXPECT_NEAR(out.C_b(32, 24).x(), 0.5, 1e-6);  // W_g < 1: C_g itself
  EXPECT_NEAR(out.D_b(32, 24), 1.5, 1e-6);
  EXPECT_TRUE(out.C_b(2, 2).isZero());          // nothing at all: black, depth 0 (invalid)
  EXPECT_EQ(out.D_b(2, 2), 0.0f);
  // three copies (W_g = 1.5 > 1): normalised, C_b = c, D_b = d
  GaussianHost three(0);
  for (int k = 0; k < 3; ++k) {
    three.means.push_back(g.means[0]);
    three.log_scales.push_back(g.log_scales[0]);
    three.quats.push_back(g.quats[0]);
    three.logit_opacities.push_back(0.0f);
    three.sh.push_back(g.sh[0]);
    three.plane_ids.push_back(0);
  }
  out = render_host(camera64(), three, GaussianHost(0), in, {}, Device::cpu());
  EXPECT_NEAR(out.W_g(32, 24), 1.5, 1e-6);
  EXPECT_NEAR(out.C_b(32, 24).y(), 0.5, 1e-6);
  EXPECT_NEAR(out.D_b(32, 24), 3.0, 1e-6);
}

TEST(RenderForward, ReflectionCompositesFrontToBackAndTerminatesEarly) {
  // Five coincident footprints with alpha 0.95 at the centre, stored back to front, colours e_k:
  // T = 1, 0.05, 0.0025, 1.25e-4; the 4th would drop T to 6.25e-6 < 1e-4, so it and the 5th are out.
  GaussianHost g(0);
  const float logit = std::log(0.95f / 0.05f);
  const Color colors[5] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}};
  for (int k = 4; k >= 0; --k) {  // depth 2 + 0.1 k
    GaussianHost one = one_gaussian({0, 0, 2.0f + 0.1f * k}, 0.04f, logit, colors[k], 1);
    g.means.push_back(one.means[0]);
    g.log_scales.push_back(one.log_scales[0]);
    g.quats.push_back(one.quats[0]);
    g.logit_opacities.push_back(logit);
    g.sh.push_back(one.sh[0]);
    g.plane_ids.push_back(1);
  }
  const HostOut out = render_host(camera64(), GaussianHost(0), g, uniform_raycast(64, 48, {0, 0, 0}, 1.0f, 1, 1), {},
                                  Device::cpu());
  const Color c = out.C_r(32, 24);
  EXPECT_NEAR(c.x(), 0.95, 1e-5);
  EXPECT_NEAR(c.y(), 0.95 * 0.05, 1e-5);
  EXPECT_NEAR(c.z(), 0.95 * 0.0025, 1e-6);
  EXPECT_NEAR(out.W_r(32, 24), 0.95 + 0.95 * 0.05 + 0.95 * 0.0025, 1e-5);
}

void expect_images_near(const HostOut& a, const HostOut& b, double tol) {
  for (size_t i = 0; i < a.C.size(); ++i) {
    ASSERT_LE((a.C[i] - b.C[i]).norm(), tol) << i;
    ASSERT_LE((a.C_r[i] - b.C_r[i]).norm(), tol) << i;
    ASSERT_NEAR(a.W_r[i], b.W_r[i], tol) << i;
    ASSERT_NEAR(a.D_b[i], b.D_b[i], tol) << i;
  }
}

TEST(RenderForward, MultiPassEqualsGroupedSinglePass) {
  const SmallScene s = small_scene(17, 96, 64);
  RenderParams p;
  const HostOut grouped = render_host(s.camera, s.base, s.refl, s.raycast, p, Device::cpu());
  p.variant = ReflectionVariant::MultiPass;
  const HostOut multi = render_host(s.camera, s.base, s.refl, s.raycast, p, Device::cpu());
  expect_images_near(grouped, multi, 1e-6);
  p.variant = ReflectionVariant::NoPlaneGrouping;
  const HostOut vanilla = render_host(s.camera, s.base, s.refl, s.raycast, p, Device::cpu());
  double diff = 0;
  for (size_t i = 0; i < grouped.C_r.size(); ++i) diff += (grouped.C_r[i] - vanilla.C_r[i]).norm();
  EXPECT_GT(diff, 1.0);
}

TEST(RenderForward, ReflectionPassAloneEqualsTheFullRendersCr) {
  const SmallScene s = small_scene(29, 96, 64);
  for (const ReflectionVariant v : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping, ReflectionVariant::MultiPass}) {
    RenderParams p;
    p.variant = v;
    const HostOut full = render_host(s.camera, s.base, s.refl, s.raycast, p, Device::cpu());
    const auto b = GaussianSet::from_host(s.base, Device::cpu());
    const auto r = GaussianSet::from_host(s.refl, Device::cpu());
    const auto rc = to_device(s.raycast, Device::cpu());
    Renderer renderer(Device::cpu(), p);
    RenderOutputs out;
    renderer.render_reflection(s.camera, r, rc.I, out);
    const ColorImage C_r = out.C_r.to_host();
    const DepthImage W_r = out.W_r.to_host();
    double energy = 0;
    for (size_t i = 0; i < C_r.size(); ++i) {
      ASSERT_EQ(C_r[i], full.C_r[i]) << to_string(v) << " pixel " << i;
      ASSERT_EQ(W_r[i], full.W_r[i]) << to_string(v) << " pixel " << i;
      energy += C_r[i].sum();
    }
    EXPECT_GT(energy, 1.0) << to_string(v);
    // A pass-3-only render is no base for a backward pass; a full render afterwards is.
    GaussianGrads vb, vr;
    const HostUpstream up = random_upstream(96, 64, 3);
    EXPECT_THROW(renderer.backward(to_device(up, Device::cpu()), vb, vr), std::logic_error);
    renderer.render(s.camera, b, r, rc, out);
    EXPECT_NO_THROW(renderer.backward(to_device(up, Device::cpu()), vb, vr));
  }
}

// render_reflection with a stop threshold (the tracking mask's): where the full C_r's mean RGB is
// <= the threshold, C_r and W_r are the full ones bit for bit; elsewhere the pixel stopped early with
// a mean above it (the mask's test, mask_source.h, gives the same answer) and no channel above the
// full one; and some
// pixels did stop early (the scene's reflections are bright enough). Every variant, every device.
TEST(RenderForward, ReflectionPassStoppedAtTheMaskThresholdGivesTheSameMask) {
  const SmallScene s = small_scene(29, 96, 64);
  // the mask's default threshold, and a lower one at which part of the bright pixels stop before the
  // end of their lists (at 0.1 this small scene's pixels cross it at their last splats)
  for (const float threshold : {0.1f, 0.02f})
    for (const Device& device : available_devices())
      for (const ReflectionVariant v : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping, ReflectionVariant::MultiPass}) {
        SCOPED_TRACE(device.to_string() + " " + to_string(v) + " threshold " + std::to_string(threshold));
        RenderParams p;
        p.variant = v;
        const auto r = GaussianSet::from_host(s.refl, device);
        const auto rc = to_device(s.raycast, device);
        Renderer renderer(device, p);
        RenderOutputs full, stopped;
        renderer.render_reflection(s.camera, r, rc.I, full);
        renderer.render_reflection(s.camera, r, rc.I, stopped, threshold);
        const ColorImage C = full.C_r.to_host(), C_s = stopped.C_r.to_host();
        const DepthImage W = full.W_r.to_host(), W_s = stopped.W_r.to_host();
        int above = 0, early = 0;
        for (size_t i = 0; i < C.size(); ++i) {
          if (!(C[i].sum() / 3.0f > threshold)) {
            ASSERT_EQ(C_s[i], C[i]) << "pixel " << i;
            ASSERT_EQ(W_s[i], W[i]) << "pixel " << i;
            continue;
          }
          ++above;
          ASSERT_GT(C_s[i].sum() / 3.0f, threshold) << "pixel " << i;
          for (int c = 0; c < 3; ++c) ASSERT_LE(C_s[i][c], C[i][c] * (1.0f + 1e-6f) + 1e-7f) << "pixel " << i;
          early += C_s[i] != C[i];
        }
        EXPECT_GT(above, 80);
        if (threshold < 0.05f) EXPECT_GT(early, 20);  // the stop path ran
      }
  Renderer cpu(Device::cpu());
  RenderOutputs out;
  const auto r = GaussianSet::from_host(s.refl, Device::cpu());
  const auto rc = to_device(s.raycast, Device::cpu());
  EXPECT_THROW(cpu.render_reflection(s.camera, r, rc.I, out, std::nanf("")), std::invalid_argument);
}

TEST(RenderForward, TiledPipelineMatchesTheDoubleReference) {
  for (auto variant : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping}) {
    const SmallScene s = small_scene(41, 72, 40);
    RenderParams p;
    p.variant = variant;
    const HostOut got = render_host(s.camera, s.base, s.refl, s.raycast, p, Device::cpu());
    const ReferenceOutputs ref =
        render_reference(s.camera, GaussiansD::from(s.base), GaussiansD::from(s.refl), s.raycast, p);
    double sum_w = 0;
    for (size_t i = 0; i < got.C.size(); ++i) {
      ASSERT_LE((got.C[i].cast<double>() - ref.C[i]).norm(), 2e-5) << i;
      ASSERT_LE((got.C_b[i].cast<double>() - ref.C_b[i]).norm(), 2e-5) << i;
      ASSERT_NEAR(got.D_b[i], ref.D_b[i], 2e-5) << i;
      ASSERT_NEAR(got.W_g[i], ref.W_g[i], 2e-5) << i;
      ASSERT_NEAR(got.W_r[i], ref.W_r[i], 2e-5) << i;
      sum_w += ref.W_g[i] + ref.W_r[i];
    }
    EXPECT_GT(sum_w, 100.0);
  }
}

std::vector<float> flatten(const HostOut& o) {
  std::vector<float> v;
  for (const ColorImage* img : {&o.C, &o.C_b, &o.C_g, &o.C_r})
    for (const Color& c : img->pixels()) v.insert(v.end(), {c.x(), c.y(), c.z()});
  for (const DepthImage* img : {&o.D_b, &o.D_g, &o.W_g, &o.W_r}) v.insert(v.end(), img->pixels().begin(), img->pixels().end());
  return v;
}

// CPU and CUDA agree within float tolerance everywhere except where an alpha lies within a few ulps
// of the 1/255 cutoff (or a depth of D_t + eps): CUDA's expf and fused multiply-adds round
// differently from the host's, so that one Gaussian may be kept on one device and skipped on the
// other, moving the pixel by ~alpha * colour <= 1e-2. At most 1 value in 10^4 may flip so.
void expect_parity_up_to_threshold_flips(const std::function<std::vector<float>(const Device&)>& body) {
  report_cuda_parity_status();
  const auto ref = body(Device::cpu());
  for (const Device& d : available_devices()) {
    if (d.is_cpu()) continue;
    SCOPED_TRACE(d.to_string());
    const auto got = body(d);
    ASSERT_EQ(got.size(), ref.size());
    size_t flips = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
      const double diff = std::abs(double(ref[i]) - double(got[i]));
      if (diff <= 1e-5 + 1e-5 * std::abs(ref[i])) continue;
      ++flips;
      EXPECT_LT(diff, 1e-2) << "element " << i << ": cpu " << ref[i] << " vs " << got[i];
    }
    EXPECT_LE(flips, ref.size() / 10000) << "values differing beyond float tolerance";
  }
}

TEST(RenderForward, EveryVariantGivesTheSameImagesOnEveryDevice) {
  const SmallScene s = small_scene(7, 200, 120);
  GaussianHost base = random_gaussians(3000, 3, 1.0f, 4.0f, s.camera.K.fx, {}, 1);
  GaussianHost refl = random_gaussians(3000, 3, 2.0f, 6.0f, s.camera.K.fx, {1, 2, 3}, 2);
  for (auto variant : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping, ReflectionVariant::MultiPass}) {
    SCOPED_TRACE(to_string(variant));
    RenderParams p;
    p.variant = variant;
    expect_parity_up_to_threshold_flips(
        [&](const Device& d) { return flatten(render_host(s.camera, base, refl, s.raycast, p, d)); });
  }
}

TEST(RenderForward, MismatchedInputsAreRejectedWithTheirNames) {
  const SmallScene s = small_scene(3);
  HostRaycast bad = s.raycast;
  bad.D_t = DepthImage(10, 10);
  try {
    render_host(s.camera, s.base, s.refl, bad, {}, Device::cpu());
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("D_t is 10x10"), std::string::npos) << e.what();
  }
  Renderer r(Device::cpu());
  GaussianGrads gb, gr;
  EXPECT_THROW(r.backward({}, gb, gr), std::logic_error);
  RenderParams p;
  p.near_plane = 0;
  EXPECT_THROW(Renderer(Device::cpu(), p), std::invalid_argument);
  EXPECT_THROW(parse_reflection_variant("fancy"), std::invalid_argument);
  EXPECT_EQ(parse_reflection_variant("multi-pass"), ReflectionVariant::MultiPass);
}

}  // namespace
}  // namespace rrg::test
