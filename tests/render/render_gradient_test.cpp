// Backward passes of pass 2 and pass 3 against central finite differences of the double-precision
// reference (render_scene.h), per parameter type of each set; CPU/CUDA parity of the gradients.
#include "core/gaussians/losses.h"
#include "core/render/renderer.h"
#include "tests/render/render_scene.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <string>

namespace rrg::test {
namespace {

struct Grads {
  GaussianHost base, refl;  // gradients stored in a GaussianHost layout (v_* per field)
};

// The gradient buffers as they are, in a GaussianHost layout.
GaussianHost raw_host_grads(const GaussianGrads& g, int degree) {
  GaussianHost h(degree);
  h.means = g.v_means.to_host();
  h.log_scales = g.v_log_scales.to_host();
  h.quats = g.v_quats.to_host();
  h.logit_opacities = g.v_logit_opacities.to_host();
  h.sh = g.v_sh.to_host();
  h.plane_ids.assign(h.means.size(), 0);
  return h;
}

// The gradients as the renderer defines them: v_* where touched = 1, zero where it is 0 (those
// entries are not written). A wrong mark therefore shows in every comparison below.
GaussianHost to_host_grads(const GaussianGrads& g, int degree) {
  GaussianHost h = raw_host_grads(g, degree);
  const std::vector<uint8_t> touched = g.touched.to_host();
  if (touched.size() != h.size()) throw std::logic_error("to_host_grads: touched has the wrong size");
  const size_t K = size_t(h.sh_coeffs());
  for (size_t i = 0; i < h.size(); ++i) {
    if (touched[i]) continue;
    h.means[i].setZero();
    h.log_scales[i].setZero();
    h.quats[i].setZero();
    h.logit_opacities[i] = 0.0f;
    for (size_t k = 0; k < K; ++k) h.sh[i * K + k].setZero();
  }
  return h;
}

Grads analytic(const SmallScene& s, const HostUpstream& up, const RenderParams& p, const Device& device) {
  const auto base = GaussianSet::from_host(s.base, device);
  const auto refl = GaussianSet::from_host(s.refl, device);
  const auto in = to_device(s.raycast, device);
  Renderer r(device, p);
  RenderOutputs out;
  r.render(s.camera, base, refl, in, out);
  GaussianGrads gb, gr;
  r.backward(to_device(up, device), gb, gr);
  return {to_host_grads(gb, s.base.sh_degree), to_host_grads(gr, s.refl.sh_degree)};
}

enum class Param { Mean, LogScale, Quat, Opacity, Sh };
const char* name(Param p) {
  switch (p) {
    case Param::Mean: return "means";
    case Param::LogScale: return "log_scales";
    case Param::Quat: return "quats";
    case Param::Opacity: return "logit_opacities";
    case Param::Sh: return "sh";
  }
  return "?";
}

// Pointers to every scalar of one parameter type in a double set, and the matching analytic values.
void scalars(GaussiansD& g, const GaussianHost& a, Param p, std::vector<double*>& x, std::vector<double>& grad) {
  for (size_t i = 0; i < g.means.size(); ++i) switch (p) {
      case Param::Mean:
        for (int k = 0; k < 3; ++k) x.push_back(&g.means[i][k]), grad.push_back(a.means[i][k]);
        break;
      case Param::LogScale:
        for (int k = 0; k < 3; ++k) x.push_back(&g.log_scales[i][k]), grad.push_back(a.log_scales[i][k]);
        break;
      case Param::Quat:
        for (int k = 0; k < 4; ++k) x.push_back(&g.quats[i][k]), grad.push_back(a.quats[i][k]);
        break;
      case Param::Opacity:
        x.push_back(&g.logit_opacities[i]), grad.push_back(a.logit_opacities[i]);
        break;
      case Param::Sh:
        break;
    }
  if (p == Param::Sh)
    for (size_t j = 0; j < g.sh.size(); ++j)
      for (int k = 0; k < 3; ++k) x.push_back(&g.sh[j][k]), grad.push_back(a.sh[j][k]);
}

struct CheckResult {
  double max_rel = 0;   // max |analytic - fd| / max |fd| over the parameter type
  double max_abs_fd = 0;
  size_t n = 0;
  size_t at_threshold = 0;  // scalars skipped: the loss jumps within +-h (a 3DGS threshold crossed)
};

// Central differences (h = 1e-6, double) of the reference loss w.r.t. one parameter type of one set.
// The renderer is piecewise smooth (alpha < 1/255 skipped, early termination, depth cull, integer
// radii); where the two one-sided differences disagree grossly a threshold lies inside +-h, the
// derivative there is not defined, and the scalar is skipped (at most 2% may be).
CheckResult check(const SmallScene& s, const HostUpstream& up, const RenderParams& p, const Grads& a, bool refl_set,
                  Param param) {
  GaussiansD base = GaussiansD::from(s.base), refl = GaussiansD::from(s.refl);
  std::vector<double*> x;
  std::vector<double> grad;
  scalars(refl_set ? refl : base, refl_set ? a.refl : a.base, param, x, grad);
  const double h = 1e-6;
  const double l0 = reference_loss(render_reference(s.camera, base, refl, s.raycast, p), up);
  std::vector<double> fd(x.size());
  std::vector<bool> smooth(x.size(), true);
  CheckResult r;
  r.n = x.size();
  for (size_t j = 0; j < x.size(); ++j) {
    const double x0 = *x[j];
    *x[j] = x0 + h;
    const double lp = reference_loss(render_reference(s.camera, base, refl, s.raycast, p), up);
    *x[j] = x0 - h;
    const double lm = reference_loss(render_reference(s.camera, base, refl, s.raycast, p), up);
    *x[j] = x0;
    fd[j] = (lp - lm) / (2 * h);
    const double fwd = (lp - l0) / h, bwd = (l0 - lm) / h;
    if (std::abs(fwd - bwd) > 1e-2 * (1.0 + std::abs(fd[j]))) {
      smooth[j] = false;
      ++r.at_threshold;
    }
  }
  EXPECT_LE(r.at_threshold, std::max<size_t>(1, x.size() / 50));
  for (size_t j = 0; j < x.size(); ++j)
    if (smooth[j]) r.max_abs_fd = std::max(r.max_abs_fd, std::abs(fd[j]));
  for (size_t j = 0; j < x.size(); ++j) {
    if (!smooth[j]) continue;
    const double err = std::abs(grad[j] - fd[j]) / r.max_abs_fd;
    if (err > r.max_rel) r.max_rel = err;
    EXPECT_LT(err, 2e-3) << name(param) << "[" << j << "]: analytic " << grad[j] << " vs fd " << fd[j];
  }
  return r;
}

struct Case {
  uint32_t seed;
  ReflectionVariant variant;
};

class RenderGradient : public ::testing::TestWithParam<Case> {};

TEST_P(RenderGradient, EveryParameterTypeOfBothSetsMatchesFiniteDifferences) {
  const SmallScene s = small_scene(GetParam().seed);
  const HostUpstream up = random_upstream(s.camera.K.width, s.camera.K.height, GetParam().seed + 1);
  RenderParams p;
  p.variant = GetParam().variant;
  const Grads a = analytic(s, up, p, Device::cpu());
  for (bool refl_set : {false, true})
    for (Param param : {Param::Mean, Param::LogScale, Param::Quat, Param::Opacity, Param::Sh}) {
      SCOPED_TRACE(std::string(refl_set ? "G_r " : "G_b ") + name(param));
      const CheckResult r = check(s, up, p, a, refl_set, param);
      EXPECT_GT(r.max_abs_fd, 1e-3) << "the scene must exercise this parameter";
      std::cout << "[grad] " << to_string(p.variant) << " seed " << GetParam().seed << (refl_set ? " G_r " : " G_b ")
                << name(param) << ": max rel err " << r.max_rel << " (" << r.n << " scalars, " << r.at_threshold
                << " at a threshold, max |g| " << r.max_abs_fd << ")\n";
    }
}

INSTANTIATE_TEST_SUITE_P(Scenes, RenderGradient,
                         ::testing::Values(Case{11, ReflectionVariant::Grouped}, Case{23, ReflectionVariant::Grouped},
                                           Case{11, ReflectionVariant::NoPlaneGrouping},
                                           Case{11, ReflectionVariant::MultiPass}));

std::vector<float> flatten(const Grads& g) {
  std::vector<float> v;
  for (const GaussianHost* h : {&g.base, &g.refl}) {
    for (const auto& m : h->means) v.insert(v.end(), m.data(), m.data() + 3);
    for (const auto& m : h->log_scales) v.insert(v.end(), m.data(), m.data() + 3);
    for (const auto& m : h->quats) v.insert(v.end(), m.data(), m.data() + 4);
    v.insert(v.end(), h->logit_opacities.begin(), h->logit_opacities.end());
    for (const auto& m : h->sh) v.insert(v.end(), m.data(), m.data() + 3);
  }
  return v;
}

// λ_rb (core/gaussians/losses.h) reaches the renderer as v_C += s R, v_C_r −= s R. Through the real
// backward that must be the gradient of λ mean(R · C_b) alone: no reflection Gaussian gets a gradient,
// and the base's match central differences of that loss computed from the reference's C_b.
TEST(RenderGradient, ReflectiveBasePriorReachesTheBaseOnly) {
  const SmallScene s = small_scene(11);
  const int w = s.camera.K.width, h = s.camera.K.height;
  const float lambda = 0.3f;
  auto v_C = DeviceImage<Color>::from_host(ColorImage(w, h, Color::Zero()), Device::cpu());
  auto v_Cr = DeviceImage<Color>::from_host(ColorImage(w, h, Color::Zero()), Device::cpu());
  const auto R = DeviceImage<float>::from_host(s.raycast.R, Device::cpu());
  const auto Cb = DeviceImage<Color>::from_host(ColorImage(w, h, Color::Zero()), Device::cpu());  // value only
  reflective_base_prior(Cb, R, &v_C, &v_Cr, lambda);
  const HostUpstream up{v_C.to_host(), v_Cr.to_host(), DepthImage(w, h, 0.0f)};
  RenderParams p;
  const Grads a = analytic(s, up, p, Device::cpu());

  ASSERT_GT(a.refl.size(), 0u);
  double refl_max = 0;
  for (float g : flatten(Grads{GaussianHost(a.base.sh_degree), a.refl})) refl_max = std::max(refl_max, double(std::abs(g)));
  EXPECT_EQ(refl_max, 0.0) << "C_r must get no gradient from the prior";

  GaussiansD base = GaussiansD::from(s.base), refl = GaussiansD::from(s.refl);
  size_t ones = 0;
  for (float r : s.raycast.R.pixels()) ones += r == 1.0f;
  ASSERT_GT(ones, 0u);
  ASSERT_LT(ones, s.raycast.R.size());
  const auto loss = [&] {
    const ReferenceOutputs out = render_reference(s.camera, base, refl, s.raycast, p);
    double L = 0;
    for (size_t u = 0; u < out.C_b.size(); ++u) L += double(s.raycast.R[u]) * out.C_b[u].sum();
    return double(lambda) * L / (3.0 * w * h);
  };
  for (Param param : {Param::Mean, Param::LogScale, Param::Opacity, Param::Sh}) {
    SCOPED_TRACE(name(param));
    std::vector<double*> x;
    std::vector<double> grad;
    scalars(base, a.base, param, x, grad);
    const double hstep = 1e-6;
    std::vector<double> fd(x.size());
    double max_fd = 0;
    for (size_t j = 0; j < x.size(); ++j) {
      const double x0 = *x[j];
      *x[j] = x0 + hstep;
      const double lp = loss();
      *x[j] = x0 - hstep;
      const double lm = loss();
      *x[j] = x0;
      fd[j] = (lp - lm) / (2 * hstep);
      max_fd = std::max(max_fd, std::abs(fd[j]));
    }
    EXPECT_GT(max_fd, 1e-5) << "the prior must move this parameter";
    size_t off = 0;
    for (size_t j = 0; j < x.size(); ++j) off += std::abs(grad[j] - fd[j]) > 2e-3 * max_fd;
    EXPECT_LE(off, std::max<size_t>(1, x.size() / 50)) << "scalars off their finite difference (thresholds allowed 2%)";
  }
}

TEST(RenderGradient, MultiPassGradientsEqualGroupedGradients) {
  const SmallScene s = small_scene(5);
  const HostUpstream up = random_upstream(s.camera.K.width, s.camera.K.height, 6);
  RenderParams p;
  const auto grouped = flatten(analytic(s, up, p, Device::cpu()));
  p.variant = ReflectionVariant::MultiPass;
  const auto multi = flatten(analytic(s, up, p, Device::cpu()));
  ASSERT_EQ(grouped.size(), multi.size());
  for (size_t i = 0; i < grouped.size(); ++i) ASSERT_NEAR(grouped[i], multi[i], 1e-5 + 1e-5 * std::abs(grouped[i])) << i;
}

// `touched` marks exactly the Gaussians with a non-zero gradient (what GaussianAdam updates): one
// appended behind the camera and one far outside the view get 0. Into zeroed buffers the unmarked
// Gaussians' gradients stay zero; into buffers holding a sentinel the marked entries are the same
// and the unmarked ones keep the sentinel (the backward does not write them).
TEST(RenderGradient, TouchedMarksExactlyTheGaussiansWithAGradient) {
  SmallScene s = small_scene(11);
  const size_t n0 = s.base.size();
  s.base.resize(n0 + 2);
  for (size_t i = n0; i < n0 + 2; ++i) {
    s.base.log_scales[i] = Eigen::Vector3f::Constant(-3.0f);
    s.base.logit_opacities[i] = 2.0f;
  }
  s.base.means[n0] = s.camera.T_wc * Eigen::Vector3f(0.0f, 0.0f, -1.0f);     // behind the camera
  s.base.means[n0 + 1] = s.camera.T_wc * Eigen::Vector3f(50.0f, 0.0f, 1.0f);  // far to the side
  const HostUpstream up = random_upstream(s.camera.K.width, s.camera.K.height, 12);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const auto base = GaussianSet::from_host(s.base, device);
    const auto refl = GaussianSet::from_host(s.refl, device);
    const auto in = to_device(s.raycast, device);
    Renderer r(device, RenderParams{});
    RenderOutputs out;
    r.render(s.camera, base, refl, in, out);
    // zeroed buffers, and buffers holding a sentinel in every entry
    GaussianGrads gb, gr, sb, sr;
    gb.reset(base.size(), base.sh_coeffs(), device);
    gr.reset(refl.size(), refl.sh_coeffs(), device);
    constexpr float kSentinel = 7.0f;
    for (auto [g, set] : {std::pair{&sb, &base}, std::pair{&sr, &refl}}) {
      const size_t n = set->size(), K = size_t(set->sh_coeffs());
      g->resize(n, int(K), device);
      g->v_means.copy_from_host(std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(kSentinel)));
      g->v_log_scales.copy_from_host(std::vector<Eigen::Vector3f>(n, Eigen::Vector3f::Constant(kSentinel)));
      g->v_quats.copy_from_host(std::vector<Eigen::Vector4f>(n, Eigen::Vector4f::Constant(kSentinel)));
      g->v_logit_opacities.copy_from_host(std::vector<float>(n, kSentinel));
      g->v_sh.copy_from_host(std::vector<Eigen::Vector3f>(n * K, Eigen::Vector3f::Constant(kSentinel)));
    }
    r.backward(to_device(up, device), gb, gr);
    r.backward(to_device(up, device), sb, sr);
    for (auto [g, sent] : {std::pair{&gb, &sb}, std::pair{&gr, &sr}}) {
      const int degree = g == &gb ? s.base.sh_degree : s.refl.sh_degree;
      const GaussianHost h = raw_host_grads(*g, degree), hs = raw_host_grads(*sent, degree);
      const std::vector<uint8_t> touched = g->touched.to_host();
      ASSERT_EQ(touched.size(), h.size());
      ASSERT_EQ(sent->touched.to_host(), touched);
      size_t marked = 0;
      const size_t K = size_t(h.sh_coeffs());
      for (size_t i = 0; i < h.size(); ++i) {
        bool nonzero = h.logit_opacities[i] != 0.0f || !h.means[i].isZero(0.0f) || !h.log_scales[i].isZero(0.0f) ||
                       !h.quats[i].isZero(0.0f);
        for (size_t k = 0; k < K; ++k) nonzero = nonzero || !h.sh[i * K + k].isZero(0.0f);
        EXPECT_EQ(touched[i] != 0, nonzero) << i;
        marked += touched[i];
        // marked: written, the same values (bit for bit on the CPU, whose backward sums in a fixed
        // order; CUDA's atomics sum in run-dependent order); unmarked: left as they were, exactly
        const float rel = device.is_cpu() ? 0.0f : 1e-5f;
        const auto same = [&](const auto& got, const auto& want) {
          if (!touched[i]) return (got.array() == kSentinel).all();
          return ((got - want).array().abs() <= rel * (1e-1f + want.array().abs())).all();
        };
        EXPECT_TRUE(same(hs.means[i], h.means[i])) << i;
        EXPECT_TRUE(same(hs.log_scales[i], h.log_scales[i])) << i;
        EXPECT_TRUE(same(hs.quats[i], h.quats[i])) << i;
        EXPECT_TRUE(same(Eigen::Matrix<float, 1, 1>(hs.logit_opacities[i]), Eigen::Matrix<float, 1, 1>(h.logit_opacities[i])))
            << i;
        for (size_t k = 0; k < K; ++k) EXPECT_TRUE(same(hs.sh[i * K + k], h.sh[i * K + k])) << i << " sh " << k;
      }
      EXPECT_GT(marked, 0u);
      EXPECT_LT(marked, h.size());
    }
    const std::vector<uint8_t> tb = gb.touched.to_host();
    EXPECT_EQ(tb[n0], 0);
    EXPECT_EQ(tb[n0 + 1], 0);
  }
}

// The gradients are linear in the upstream, however small it is: a mean loss over a 640x480 image
// sends ~1e-6 per pixel and channel. A backward that skips "zero" pixels by a tolerance (Eigen's
// isZero() is |x| <= 1e-5) dropped most of them, and the reflection set stopped learning at
// 512x384 and above. The upstream is scaled by 1e-7 (v_D_b too) on every device.
TEST(RenderGradient, GradientsScaleWithATinyUpstream) {
  const SmallScene s = small_scene(31, 80, 56);
  const HostUpstream up = random_upstream(80, 56, 32);
  constexpr float kTiny = 1e-7f;
  HostUpstream tiny = up;
  for (auto* im : {&tiny.v_C, &tiny.v_C_r})
    for (size_t i = 0; i < im->size(); ++i) (*im)[i] *= kTiny;
  for (size_t i = 0; i < tiny.v_D_b.size(); ++i) tiny.v_D_b[i] *= kTiny;
  for (const Device& d : available_devices()) {
    SCOPED_TRACE(d.to_string());
    for (auto variant : {ReflectionVariant::Grouped, ReflectionVariant::MultiPass}) {
      SCOPED_TRACE(to_string(variant));
      RenderParams p;
      p.variant = variant;
      const std::vector<float> g = flatten(analytic(s, up, p, d)), t = flatten(analytic(s, tiny, p, d));
      ASSERT_EQ(g.size(), t.size());
      double max_g = 0;
      for (float x : g) max_g = std::max(max_g, double(std::abs(x)));
      ASSERT_GT(max_g, 0.0);
      size_t nonzero = 0;
      for (size_t i = 0; i < g.size(); ++i) {
        nonzero += g[i] != 0.0f;
        ASSERT_NEAR(t[i] / kTiny, g[i], 1e-3 * max_g) << "scalar " << i;
      }
      EXPECT_GT(nonzero, g.size() / 4) << "the scene must give most parameters a gradient";
    }
  }
}

TEST(RenderGradient, BackwardParityOnEveryDevice) {
  const SmallScene s = small_scene(31, 80, 56);
  const HostUpstream up = random_upstream(80, 56, 32);
  for (auto variant : {ReflectionVariant::Grouped, ReflectionVariant::NoPlaneGrouping, ReflectionVariant::MultiPass}) {
    SCOPED_TRACE(to_string(variant));
    RenderParams p;
    p.variant = variant;
    // atomics sum in a different order on each device: float tolerance
    expect_device_parity<float>([&](const Device& d) { return flatten(analytic(s, up, p, d)); }, 1e-4, 1e-3);
  }
}

}  // namespace
}  // namespace rrg::test
