// The CPU projection (project_cpu.cpp: eight Gaussians per vector loop) against the per-Gaussian
// loop that CUDA runs, on Gaussians of every kind: in view, culled for each reason, clamped at the
// radius cap and at the exponential's range, in a trailing partial block.
#include "core/render/project_impl.h"
#include "tests/render/render_scene.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace rrg {
namespace {

kernel::View test_view(int sh_degree, int sh_stride) {
  kernel::View v{};
  const int w = 64, h = 48;
  const float f = 0.9f * float(w);
  const Eigen::Isometry3f T_wc = Eigen::Translation3f(0.2f, -0.1f, 0.3f) *
                                 Eigen::AngleAxisf(0.15f, Eigen::Vector3f(0.3f, 1.0f, 0.2f).normalized());
  const Eigen::Matrix3f R_cw = T_wc.rotation().transpose();
  const Eigen::Vector3f t_cw = -R_cw * T_wc.translation();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) v.R_cw[r * 3 + c] = R_cw(r, c);
    v.t_cw[r] = t_cw[r];
    v.center_w[r] = T_wc.translation()[r];
  }
  v.fx = v.fy = f;
  v.cx = 0.5f * float(w - 1);
  v.cy = 0.5f * float(h - 1);
  v.width = w;
  v.height = h;
  v.near_plane = 0.01f;
  v.low_pass = 0.3f;
  v.max_radius = 24.0f;
  v.sh_degree = sh_degree;
  v.sh_stride = sh_stride;
  return v;
}

// 8 * 37 + 5 Gaussians, mostly in view (test_view's camera), with every 5th one made a case:
// behind the camera, beyond the radius cap of the image, zero quaternion, huge (radius capped),
// opacity logits past the exponential's clamp, near the image border, a NaN scale, a point.
GaussianHost mixed_gaussians(int sh_degree) {
  const int n = 8 * 37 + 5;
  GaussianHost g = test::random_gaussians(n, sh_degree, 0.5f, 4.0f, 0.9f * 64.0f, {}, 11);
  const Eigen::Isometry3f T_wc = Eigen::Translation3f(0.2f, -0.1f, 0.3f) *
                                 Eigen::AngleAxisf(0.15f, Eigen::Vector3f(0.3f, 1.0f, 0.2f).normalized());
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3f& m = g.means[size_t(i)];
    switch (i % 5 == 0 ? (i / 5) % 8 : -1) {
      case 0: m.z() = -m.z(); break;                          // behind the camera
      case 1: m.x() += 10.0f * m.z(); break;                  // far beyond the image
      case 2: g.quats[size_t(i)].setZero(); break;            // no rotation
      case 3: g.log_scales[size_t(i)].setConstant(1.0f); break;  // radius capped
      case 4: g.logit_opacities[size_t(i)] = (i % 2 ? 200.0f : -200.0f); break;
      case 5: m.x() = 0.62f * m.z(); break;                   // just past the border, still touching
      case 6: g.log_scales[size_t(i)].x() = NAN; break;          // no covariance
      case 7: g.log_scales[size_t(i)].setConstant(-30.0f); break;  // point-like: the low-pass footprint
      default: break;
    }
    m = T_wc * m;
  }
  return g;
}

kernel::GaussianViews views_of(const GaussianHost& g) {
  kernel::GaussianViews v;
  v.means = {g.means.data(), int64_t(g.means.size())};
  v.log_scales = {g.log_scales.data(), int64_t(g.log_scales.size())};
  v.quats = {g.quats.data(), int64_t(g.quats.size())};
  v.logit_opacities = {g.logit_opacities.data(), int64_t(g.logit_opacities.size())};
  v.sh = {g.sh.data(), int64_t(g.sh.size())};
  v.plane_ids = {g.plane_ids.data(), int64_t(g.plane_ids.size())};
  return v;
}

TEST(Projection, LanesMatchThePerGaussianLoop) {
  for (const int stored : {0, 1, 3})
    for (int degree = 0; degree <= stored; ++degree) {
      SCOPED_TRACE("SH degree " + std::to_string(degree) + " of " + std::to_string(stored));
      const GaussianHost g = mixed_gaussians(stored);
      const kernel::View view = test_view(degree, g.sh_coeffs());
      const int64_t n = int64_t(g.size());
      std::vector<kernel::Splat> s_lanes(size_t(n), kernel::Splat{{7, 7}, {7, 7, 7}, 7, {7, 7, 7}, 7});
      std::vector<kernel::Splat> s_ref = s_lanes;
      std::vector<kernel::TileRect> r_lanes(size_t(n), kernel::TileRect{7, 7, 9, 9}), r_ref = r_lanes;
      kernel::project_splats_cpu(view, views_of(g), {s_lanes.data(), n}, {r_lanes.data(), n});
      kernel::project_splats_per_gaussian_cpu(view, views_of(g), {s_ref.data(), n}, {r_ref.data(), n});
      int visible = 0;
      for (int64_t i = 0; i < n; ++i) {
        ASSERT_EQ(std::memcmp(&s_lanes[size_t(i)], &s_ref[size_t(i)], sizeof(kernel::Splat)), 0) << "Gaussian " << i;
        ASSERT_EQ(std::memcmp(&r_lanes[size_t(i)], &r_ref[size_t(i)], sizeof(kernel::TileRect)), 0) << "Gaussian " << i;
        visible += r_ref[size_t(i)].count() > 0;
      }
      // both kinds are there, and every case above was culled or kept as it should be
      EXPECT_GT(visible, n / 2);
      EXPECT_LT(visible, n - n / 10);
      for (int64_t i = 0; i < n; i += 5) {
        const int kind = int(i / 5) % 8;
        const bool kept = r_ref[size_t(i)].count() > 0;
        if (kind == 0 || kind == 1 || kind == 2 || kind == 6) EXPECT_FALSE(kept) << "Gaussian " << i << ", case " << kind;
        if (kind == 7) {
          EXPECT_TRUE(kept) << "Gaussian " << i;
          EXPECT_NEAR(s_ref[size_t(i)].conic[0], 1.0f / 0.3f, 1e-3f);  // Sigma' = 0.3 I
        }
        if (kind == 3) {
          EXPECT_TRUE(kept) << "Gaussian " << i;
          EXPECT_GE(r_ref[size_t(i)].count(), 4) << "Gaussian " << i;  // 2x2 tiles or more at a 24 px radius
        }
        if (kind == 4 && kept) {
          const float o = s_ref[size_t(i)].opacity;
          EXPECT_TRUE(o == 1.0f || (o >= 0.0f && o < 1e-30f)) << o;
        }
      }
    }
}

// The gradients: every splat gradient random, except whole blocks of eight and single Gaussians
// left at zero (their entries must stay unwritten); compared over whole buffers filled with a
// sentinel first, `touched` included.
TEST(Projection, BackwardLanesMatchThePerGaussianLoop) {
  for (const int stored : {0, 2, 3})
    for (int degree = 0; degree <= stored; ++degree) {
      SCOPED_TRACE("SH degree " + std::to_string(degree) + " of " + std::to_string(stored));
      const GaussianHost g = mixed_gaussians(stored);
      const kernel::View view = test_view(degree, g.sh_coeffs());
      const int64_t n = int64_t(g.size()), K = g.sh_coeffs();
      std::mt19937 rng(5);
      std::uniform_real_distribution<float> u(-1.0f, 1.0f);
      std::vector<kernel::SplatGrad> v_splats(static_cast<size_t>(n));
      const auto zero_at = [](int64_t i) { return (i / 8) % 4 == 1 || i % 7 == 3; };  // blocks; lanes in blocks
      for (int64_t i = 0; i < n; ++i) {
        if (zero_at(i)) continue;
        kernel::SplatGrad& s = v_splats[size_t(i)];
        for (float* f : {&s.mean[0], &s.mean[1], &s.conic[0], &s.conic[1], &s.conic[2], &s.opacity, &s.color[0],
                         &s.color[1], &s.color[2], &s.depth})
          *f = u(rng);
      }
      struct Grads {
        std::vector<Eigen::Vector3f> means, log_scales, sh;
        std::vector<Eigen::Vector4f> quats;
        std::vector<float> logits;
        std::vector<uint8_t> touched;
        kernel::GaussianGradViews views() {
          return {{means.data(), int64_t(means.size())},   {log_scales.data(), int64_t(log_scales.size())},
                  {quats.data(), int64_t(quats.size())},   {logits.data(), int64_t(logits.size())},
                  {sh.data(), int64_t(sh.size())},         {touched.data(), int64_t(touched.size())}};
        }
      };
      const auto sentinel = [&] {
        return Grads{std::vector<Eigen::Vector3f>(size_t(n), Eigen::Vector3f::Constant(9)),
                     std::vector<Eigen::Vector3f>(size_t(n), Eigen::Vector3f::Constant(9)),
                     std::vector<Eigen::Vector3f>(size_t(n * K), Eigen::Vector3f::Constant(9)),
                     std::vector<Eigen::Vector4f>(size_t(n), Eigen::Vector4f::Constant(9)),
                     std::vector<float>(size_t(n), 9.0f), std::vector<uint8_t>(size_t(n), 9)};
      };
      Grads lanes = sentinel(), ref = sentinel();
      const Span<const kernel::SplatGrad> vs{v_splats.data(), n};
      kernel::project_bwd_cpu(view, views_of(g), vs, lanes.views());
      kernel::project_bwd_per_gaussian_cpu(view, views_of(g), vs, ref.views());
      const auto same = [](const auto& a, const auto& b) {
        return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
      };
      EXPECT_TRUE(same(lanes.means, ref.means));
      EXPECT_TRUE(same(lanes.log_scales, ref.log_scales));
      EXPECT_TRUE(same(lanes.quats, ref.quats));
      EXPECT_TRUE(same(lanes.logits, ref.logits));
      EXPECT_TRUE(same(lanes.sh, ref.sh));
      EXPECT_TRUE(same(lanes.touched, ref.touched));
      int touched = 0, unwritten = 0;
      for (int64_t i = 0; i < n; ++i) {
        touched += ref.touched[size_t(i)] == 1;
        if (zero_at(i)) {
          EXPECT_EQ(ref.touched[size_t(i)], 0);
          unwritten += ref.logits[size_t(i)] == 9.0f;
        }
      }
      EXPECT_GT(touched, n / 3);
      EXPECT_GT(unwritten, n / 5);
    }
}

}  // namespace
}  // namespace rrg
