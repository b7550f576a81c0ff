// Adam: a known answer against a hand-written double-precision Adam, the visibility rule, and the
// state following prune (Compaction) and append (grow); CPU/CUDA parity.
#include "core/gaussians/adam.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rrg {
namespace {

GaussianHost three(int degree) {
  GaussianHost g(degree);
  g.resize(3);
  for (int i = 0; i < 3; ++i) {
    g.means[i] = Eigen::Vector3f(float(i), 1, 2);
    g.log_scales[i] = Eigen::Vector3f::Constant(-4.0f);
    g.logit_opacities[i] = 0.1f * float(i);
  }
  return g;
}

// Gradients: Gaussian 0 and 2 get values, Gaussian 1 gets none (invisible).
void fill_grads(GaussianGrads& g, size_t n, int K, float scale, const Device& dev) {
  g.reset(n, K, dev);
  std::vector<Eigen::Vector3f> vm(n, Eigen::Vector3f::Zero()), vs(n, Eigen::Vector3f::Zero()), vsh(n * K, Eigen::Vector3f::Zero());
  std::vector<Eigen::Vector4f> vq(n, Eigen::Vector4f::Zero());
  std::vector<float> vo(n, 0.0f);
  for (size_t i = 0; i < n; i += 2) {
    vm[i] = Eigen::Vector3f(0.5f, -2.0f, 0.0f) * scale;
    vs[i] = Eigen::Vector3f(1.0f, 0.0f, -1.0f) * scale;
    vq[i] = Eigen::Vector4f(0.1f, 0.0f, 0.0f, 0.3f) * scale;
    vo[i] = -0.25f * scale;
    for (int k = 0; k < K; ++k) vsh[i * K + k] = Eigen::Vector3f(0.01f, 0.0f, 0.02f) * float(k + 1) * scale;
  }
  g.v_means.copy_from_host(vm);
  g.v_log_scales.copy_from_host(vs);
  g.v_quats.copy_from_host(vq);
  g.v_logit_opacities.copy_from_host(vo);
  g.v_sh.copy_from_host(vsh);
}

// Reference Adam in double for one scalar over a sequence of gradients.
double adam_ref(double p, const std::vector<double>& grads, double lr) {
  double m = 0, v = 0;
  for (size_t t = 1; t <= grads.size(); ++t) {
    const double g = grads[t - 1];
    m = 0.9 * m + 0.1 * g;
    v = 0.999 * v + 0.001 * g * g;
    p -= lr * (m / (1 - std::pow(0.9, double(t)))) / (std::sqrt(v / (1 - std::pow(0.999, double(t)))) + 1e-15);
  }
  return p;
}

TEST(Adam, KnownAnswerVisibilityAndParity) {
  const int degree = 1, K = 4;
  const GaussianHost start = three(degree);
  const AdamParams params{AdamLearningRates::base()};
  const auto got = test::expect_device_parity<double>(
      [&](const Device& dev) {
        GaussianSet set = GaussianSet::from_host(start, dev);
        GaussianAdam adam(params, degree, dev);
        adam.grow(set.size());
        GaussianGrads g;
        fill_grads(g, 3, K, 1.0f, dev);
        EXPECT_EQ(adam.step(set, g), 2);
        fill_grads(g, 3, K, -0.5f, dev);
        EXPECT_EQ(adam.step(set, g), 2);
        const GaussianHost h = set.to_host();
        std::vector<double> out;
        for (size_t i = 0; i < 3; ++i) {
          for (int c = 0; c < 3; ++c) out.push_back(h.means[i][c]);
          for (int c = 0; c < 3; ++c) out.push_back(h.log_scales[i][c]);
          for (int c = 0; c < 4; ++c) out.push_back(h.quats[i][c]);
          out.push_back(h.logit_opacities[i]);
          for (int k = 0; k < K; ++k)
            for (int c = 0; c < 3; ++c) out.push_back(h.sh[i * K + k][c]);
        }
        for (int32_t s : adam.to_host().steps) out.push_back(s);
        return out;
      },
      1e-7, 1e-6);
  // Gaussian 0 against the reference: gradients g then -0.5 g.
  const AdamLearningRates lr = params.lr;
  auto ref = [&](double p0, double g, double rate) { return adam_ref(p0, {g, -0.5 * g}, rate); };
  EXPECT_NEAR(got[0], ref(0.0, 0.5, lr.mean), 1e-7);
  EXPECT_NEAR(got[1], ref(1.0, -2.0, lr.mean), 1e-7);
  EXPECT_NEAR(got[2], 2.0, 0.0);  // zero gradient component: m = v = 0, no move
  EXPECT_NEAR(got[3], ref(-4.0, 1.0, lr.log_scale), 1e-6);
  EXPECT_NEAR(got[6], ref(1.0, 0.1, lr.rotation), 1e-7);
  EXPECT_NEAR(got[10], ref(0.0, -0.25, lr.opacity), 1e-6);
  // SH: the DC band's three channels with lr_sh0, every later coefficient with lr_sh_rest (the
  // first and the last of each run, where a wrong boundary of the two rates would show).
  EXPECT_NEAR(got[11], ref(0.0, 0.01, lr.sh0), 1e-7);
  EXPECT_EQ(got[12], 0.0);
  EXPECT_NEAR(got[13], ref(0.0, 0.02, lr.sh0), 1e-7);
  EXPECT_NEAR(got[14], ref(0.0, 0.02, lr.sh_rest), 1e-7);
  EXPECT_NEAR(got[22], ref(0.0, 0.08, lr.sh_rest), 1e-7);
  // Gaussian 1 had no gradient: untouched.
  const size_t per = 11 + 3 * K;
  EXPECT_EQ(got[per + 0], 1.0);
  EXPECT_EQ(got[per + 3], -4.0);
  EXPECT_FLOAT_EQ(float(got[per + 10]), 0.1f);
  // step counts 2, 0, 2
  EXPECT_EQ(got[3 * per + 0], 2);
  EXPECT_EQ(got[3 * per + 1], 0);
  EXPECT_EQ(got[3 * per + 2], 2);
}

// The renderer's backward marks the Gaussians with a non-zero gradient in `touched`; Adam then
// updates exactly those, without reading their gradients. A mark decides: a Gaussian marked 0 stays
// put even with gradients, and the result with the marks equals the one read from the gradients.
TEST(Adam, TouchedMarksDecideWhichGaussiansMove) {
  const int degree = 1, K = 4;
  for (const Device& dev : available_devices()) {
    SCOPED_TRACE(dev.to_string());
    auto run = [&](const std::vector<uint8_t>* marks) {
      GaussianSet set = GaussianSet::from_host(three(degree), dev);
      GaussianAdam adam(AdamParams{AdamLearningRates::base()}, degree, dev);
      adam.grow(set.size());
      GaussianGrads g;
      fill_grads(g, 3, K, 1.0f, dev);
      if (marks) {
        g.touched = Buffer<uint8_t>(3, dev);
        g.touched.copy_from_host(*marks);
      }
      const int64_t updated = adam.step(set, g);
      return std::pair{updated, set.to_host()};
    };
    const std::vector<uint8_t> exact{1, 0, 1}, only_first{1, 0, 0};
    const auto [n_scan, scan] = run(nullptr);
    const auto [n_marked, marked] = run(&exact);
    const auto [n_first, first] = run(&only_first);
    EXPECT_EQ(n_scan, 2);
    EXPECT_EQ(n_marked, 2);
    EXPECT_EQ(n_first, 1);
    for (size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(scan.means[i], marked.means[i]) << i;
      EXPECT_EQ(scan.log_scales[i], marked.log_scales[i]) << i;
      EXPECT_EQ(scan.logit_opacities[i], marked.logit_opacities[i]) << i;
    }
    EXPECT_EQ(first.means[0], scan.means[0]);
    EXPECT_NE(scan.means[2], three(degree).means[2]);     // moved when marked
    EXPECT_EQ(first.means[2], three(degree).means[2]);    // stays when not, gradients or not
    EXPECT_EQ(first.logit_opacities[2], three(degree).logit_opacities[2]);
    // a mark array of the wrong size is an error, not a read past its end
    GaussianSet set = GaussianSet::from_host(three(degree), dev);
    GaussianAdam adam(AdamParams{}, degree, dev);
    adam.grow(set.size());
    GaussianGrads g;
    fill_grads(g, 3, K, 1.0f, dev);
    g.touched = Buffer<uint8_t>(2, dev);
    EXPECT_THROW(adam.step(set, g), std::invalid_argument);
  }
}

TEST(Adam, StateFollowsPruneAndAppend) {
  const int degree = 0, K = 1;
  for (const Device& dev : available_devices()) {
    SCOPED_TRACE(dev.to_string());
    GaussianSet set = GaussianSet::from_host(three(degree), dev);
    GaussianAdam adam(AdamParams{}, degree, dev);
    adam.grow(set.size());
    GaussianGrads g;
    fill_grads(g, 3, K, 1.0f, dev);
    adam.step(set, g);
    const AdamStateHost before = adam.to_host();
    // prune Gaussian 0: Gaussian 2 moves into slot 0 (tail fill)
    const Compaction c = set.prune({0, 1, 1});
    adam.compact(c);
    ASSERT_EQ(adam.size(), 2u);
    const AdamStateHost after = adam.to_host();
    const int s = before.stride;
    for (int j = 0; j < s; ++j) {
      EXPECT_EQ(after.m[size_t(j)], before.m[size_t(2 * s + j)]);
      EXPECT_EQ(after.v[size_t(j)], before.v[size_t(2 * s + j)]);
      EXPECT_EQ(after.m[size_t(s + j)], before.m[size_t(s + j)]);
    }
    EXPECT_EQ(after.steps, (std::vector<int32_t>{1, 0}));
    // append two: new state is zero, old kept
    GaussianHost more = three(degree);
    more.resize(2);
    set.append(more);
    adam.grow(set.size());
    const AdamStateHost grown = adam.to_host();
    ASSERT_EQ(grown.steps, (std::vector<int32_t>{1, 0, 0, 0}));
    for (int j = 0; j < s; ++j) {
      EXPECT_EQ(grown.m[size_t(j)], after.m[size_t(j)]);
      EXPECT_EQ(grown.m[size_t(2 * s + j)], 0.0f);
      EXPECT_EQ(grown.v[size_t(3 * s + j)], 0.0f);
    }
    // sizes must agree
    GaussianGrads g4;
    fill_grads(g4, 4, K, 1.0f, dev);
    EXPECT_EQ(adam.step(set, g4), 2);  // Gaussians 0 and 2 have gradients
    set.append(more);
    EXPECT_THROW(adam.step(set, g4), std::invalid_argument);
  }
}

// Host export / import (session snapshots): a restored optimiser takes the next step exactly as
// the original; a state of another SH degree or with inconsistent lengths is refused.
TEST(Adam, HostStateRoundTripContinuesExactly) {
  const int degree = 1, K = 4;
  for (const Device& dev : available_devices()) {
    SCOPED_TRACE(dev.to_string());
    GaussianSet a = GaussianSet::from_host(three(degree), dev);
    GaussianAdam adam_a(AdamParams{}, degree, dev);
    adam_a.grow(a.size());
    GaussianGrads g;
    fill_grads(g, 3, K, 1.0f, dev);
    adam_a.step(a, g);
    adam_a.step(a, g);
    // a copy of the set and the optimiser through host memory
    GaussianSet b = GaussianSet::from_host(a.to_host(), dev);
    GaussianAdam adam_b(AdamParams{}, degree, dev);
    adam_b.from_host(adam_a.to_host());
    ASSERT_EQ(adam_b.size(), 3u);
    fill_grads(g, 3, K, -0.5f, dev);
    adam_a.step(a, g);
    adam_b.step(b, g);
    const GaussianHost ha = a.to_host(), hb = b.to_host();
    for (size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(ha.means[i], hb.means[i]) << i;
      EXPECT_EQ(ha.logit_opacities[i], hb.logit_opacities[i]) << i;
    }
    EXPECT_EQ(ha.sh, hb.sh);
    const AdamStateHost sa = adam_a.to_host(), sb = adam_b.to_host();
    EXPECT_EQ(sa.m, sb.m);
    EXPECT_EQ(sa.v, sb.v);
    EXPECT_EQ(sa.steps, (std::vector<int32_t>{3, 0, 3}));
    EXPECT_EQ(sa.steps, sb.steps);
    GaussianAdam other_degree(AdamParams{}, 0, dev);
    EXPECT_THROW(other_degree.from_host(sa), std::invalid_argument);
    AdamStateHost short_m = sa;
    short_m.m.pop_back();
    EXPECT_THROW(adam_b.from_host(short_m), std::invalid_argument);
  }
}

TEST(Adam, RejectsBadParams) {
  AdamParams p;
  p.beta1 = 1.0f;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = AdamParams{};
  p.lr.mean = -1.0f;
  EXPECT_THROW(GaussianAdam(p, 0, Device::cpu()), std::invalid_argument);
  EXPECT_EQ(AdamLearningRates::reflection().opacity, 1e-3f);
  EXPECT_EQ(AdamLearningRates::base().opacity, 5e-2f);
}

}  // namespace
}  // namespace rrg
