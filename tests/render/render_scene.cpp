#include "tests/render/render_scene.h"

#include "core/render/blend_device.h"
#include "core/render/project_device.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace rrg::test {

namespace {
using Vec3d = Eigen::Vector3d;

template <class T>
DeviceImage<T> up(const Image<T>& img, const Device& d) {
  return DeviceImage<T>::from_host(img, d);
}
}  // namespace

RaycastInputs to_device(const HostRaycast& h, const Device& device) {
  return {up(h.C_t, device), up(h.D_t, device), up(h.I, device), up(h.R, device)};
}

RenderUpstream to_device(const HostUpstream& u, const Device& device) {
  return {up(u.v_C, device), up(u.v_D_b, device), up(u.v_C_r, device)};
}

GaussianHost random_gaussians(int n, int sh_degree, float z0, float z1, float f,
                              const std::vector<int32_t>& planes, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), u01(0.0f, 1.0f);
  GaussianHost g(sh_degree);
  g.resize(size_t(n));
  const int K = g.sh_coeffs();
  for (int i = 0; i < n; ++i) {
    const float z = z0 + (z1 - z0) * u01(rng);
    g.means[i] = {0.45f * z * u(rng), 0.35f * z * u(rng), z};
    for (int a = 0; a < 3; ++a) g.log_scales[i][a] = std::log(z / f * (1.5f + 2.5f * u01(rng)));
    g.quats[i] = Eigen::Vector4f(u(rng), u(rng), u(rng), u(rng)) + Eigen::Vector4f(0.5f, 0, 0, 0);
    g.logit_opacities[i] = 1.5f * u(rng);
    for (int k = 0; k < K; ++k) g.sh[size_t(i) * K + k] = Eigen::Vector3f(u(rng), u(rng), u(rng)) * (k == 0 ? 0.8f : 0.25f);
    g.plane_ids[i] = planes.empty() ? 0 : planes[size_t(i) % planes.size()];
  }
  return g;
}

SmallScene small_scene(uint32_t seed, int w, int h) {
  SmallScene s;
  const float f = 0.9f * float(w);
  s.camera.K = {f, f, 0.5f * float(w - 1), 0.5f * float(h - 1), w, h};
  // T_wc: a small rotation and translation; Gaussians are placed in the camera frame then mapped.
  const Eigen::Isometry3f T_wc = Eigen::Translation3f(0.2f, -0.1f, 0.3f) *
                                 Eigen::AngleAxisf(0.15f, Eigen::Vector3f(0.3f, 1.0f, 0.2f).normalized());
  s.camera.T_wc = T_wc;
  s.base = random_gaussians(12, 3, 1.5f, 3.0f, f, {}, seed);
  s.refl = random_gaussians(12, 3, 2.5f, 4.5f, f, {1, 2}, seed + 7);
  for (auto* g : {&s.base, &s.refl})
    for (auto& m : g->means) m = T_wc * m;
  std::mt19937 rng(seed + 99);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  s.raycast.C_t = ColorImage(w, h);
  s.raycast.D_t = DepthImage(w, h);
  s.raycast.I = Image<int32_t>(w, h);
  s.raycast.R = Image<float>(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      s.raycast.C_t(x, y) = {u01(rng), u01(rng), u01(rng)};
      // tilted surface at 2.0-2.6 m, missed in the top-right corner
      s.raycast.D_t(x, y) = (x > 3 * w / 4 && y < h / 4) ? 0.0f : 2.0f + 0.6f * float(x) / float(w);
      s.raycast.I(x, y) = y >= h - 3 ? 0 : (x < w / 2 ? 1 : 2);
      s.raycast.R(x, y) = (y >= 2 && y < 5) ? 0.0f : 1.0f;
    }
  return s;
}

HostUpstream random_upstream(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  HostUpstream up{ColorImage(w, h), ColorImage(w, h), DepthImage(w, h)};
  for (int i = 0; i < w * h; ++i) {
    up.v_C[size_t(i)] = {u(rng), u(rng), u(rng)};
    up.v_C_r[size_t(i)] = {u(rng), u(rng), u(rng)};
    up.v_D_b[size_t(i)] = u(rng);
  }
  return up;
}

GaussiansD GaussiansD::from(const GaussianHost& h) {
  GaussiansD d;
  d.sh_degree = h.sh_degree;
  for (size_t i = 0; i < h.size(); ++i) {
    d.means.push_back(h.means[i].cast<double>());
    d.log_scales.push_back(h.log_scales[i].cast<double>());
    d.quats.push_back(h.quats[i].cast<double>());
    d.logit_opacities.push_back(h.logit_opacities[i]);
    d.plane_ids.push_back(h.plane_ids[i]);
  }
  for (const auto& c : h.sh) d.sh.push_back(c.cast<double>());
  return d;
}

namespace {

kernel::ViewT<double> view_d(const RenderCamera& cam, const RenderParams& p, int set_degree) {
  kernel::ViewT<double> v{};
  const Eigen::Matrix3d R_cw = cam.T_wc.rotation().cast<double>().transpose();
  const Eigen::Vector3d c = cam.T_wc.translation().cast<double>();
  // the renderer computes R_cw and t_cw in float; do the same, then widen
  const Eigen::Matrix3f R_f = cam.T_wc.rotation().transpose();
  const Eigen::Vector3f t_f = -R_f * cam.T_wc.translation();
  (void)R_cw;
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) v.R_cw[r * 3 + col] = R_f(r, col);
    v.t_cw[r] = t_f[r];
    v.center_w[r] = c[r];
  }
  v.fx = cam.K.fx, v.fy = cam.K.fy, v.cx = cam.K.cx, v.cy = cam.K.cy;
  v.width = cam.K.width, v.height = cam.K.height;
  v.near_plane = p.near_plane, v.low_pass = p.low_pass, v.max_radius = p.max_radius_px;
  v.sh_degree = std::min(p.sh_degree, set_degree);
  v.sh_stride = sh_coeff_count(set_degree);
  return v;
}

struct ProjectedD {
  std::vector<kernel::SplatT<double>> splats;
  std::vector<kernel::TileRect> rects;
};

ProjectedD project_all(const kernel::ViewT<double>& v, const GaussiansD& g) {
  ProjectedD p;
  for (size_t i = 0; i < g.means.size(); ++i) {
    kernel::GaussianInT<double, Eigen::Vector3d> gi{g.means[i], g.log_scales[i], g.quats[i], g.logit_opacities[i],
                                                    &g.sh[i * size_t(v.sh_stride)]};
    kernel::SplatT<double> s{};
    double radius = 0;
    const bool ok = kernel::project_gaussian<double, Eigen::Vector3d>(v, gi, s, radius);
    p.splats.push_back(s);
    p.rects.push_back(ok ? kernel::tile_rect(v, s, radius) : kernel::TileRect{});
  }
  return p;
}

bool in_rect(const kernel::TileRect& r, int x, int y) {
  const int tx = x / kernel::kTileSize, ty = y / kernel::kTileSize;
  return tx >= r.x0 && tx < r.x1 && ty >= r.y0 && ty < r.y1;
}

}  // namespace

ReferenceOutputs render_reference(const RenderCamera& camera, const GaussiansD& base, const GaussiansD& refl,
                                  const HostRaycast& in, const RenderParams& params) {
  const int w = camera.K.width, h = camera.K.height;
  const ProjectedD pb = project_all(view_d(camera, params, base.sh_degree), base);
  const ProjectedD pr = project_all(view_d(camera, params, refl.sh_degree), refl);
  ReferenceOutputs out;
  out.C.resize(size_t(w * h));
  out.C_b = out.C_r = out.C;
  out.D_b.resize(size_t(w * h));
  out.W_g = out.W_r = out.D_b;
  // pass 3 order: by float depth, ties by index (as the stable (tile, depth) sort)
  std::vector<size_t> order(pr.splats.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return float(pr.splats[a].depth) < float(pr.splats[b].depth); });
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t u = size_t(y) * w + x;
      const double px = x, py = y, D_t = in.D_t(x, y);
      kernel::BaseAccumT<double> acc;
      for (size_t i = 0; i < pb.splats.size(); ++i)
        if (in_rect(pb.rects[i], x, y)) kernel::base_accumulate(acc, pb.splats[i], px, py, D_t, double(params.eps));
      kernel::base_resolve(acc, Vec3d(in.C_t(x, y).cast<double>()), D_t, out.C_b[u], out.D_b[u]);
      out.W_g[u] = acc.W_g;
      kernel::ReflStateT<double> st;
      const int32_t I = in.I(x, y);
      const bool grouped = params.variant != ReflectionVariant::NoPlaneGrouping;
      if (!grouped || I != 0)
        for (size_t i : order) {
          if (!in_rect(pr.rects[i], x, y) || (grouped && refl.plane_ids[i] != I)) continue;
          if (!kernel::refl_step(st, pr.splats[i], px, py)) break;
        }
      out.C_r[u] = st.C;
      out.W_r[u] = st.W;
      out.C[u] = out.C_b[u] + double(in.R(x, y)) * st.C;
    }
  return out;
}

double reference_loss(const ReferenceOutputs& out, const HostUpstream& up) {
  double L = 0;
  for (size_t u = 0; u < out.C.size(); ++u)
    L += up.v_C[u].cast<double>().dot(out.C[u]) + double(up.v_D_b[u]) * out.D_b[u] +
         up.v_C_r[u].cast<double>().dot(out.C_r[u]);
  return L;
}

}  // namespace rrg::test
