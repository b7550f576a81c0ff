#include "core/gaussians/densify.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <spdlog/spdlog.h>

namespace rrg {

namespace {

constexpr float kShC0 = 0.28209479177387814f;  // SH band 0: c = C0 · f_dc + 0.5

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Uniform in [0, 1) from (seed, pixel index).
float pixel_uniform(uint64_t seed, int64_t pixel) {
  return float(splitmix64(seed ^ splitmix64(uint64_t(pixel))) >> 40) / float(1ull << 24);
}

float color_error(const Color& a, const Color& b) { return (a - b).cwiseAbs().sum() / 3.0f; }

void check_image(const auto* im, const Intrinsics& K, const char* name) {
  if (!im) throw std::invalid_argument(std::string("densify: ") + name + " is missing");
  if (im->width() != K.width || im->height() != K.height)
    throw std::invalid_argument(std::string("densify: ") + name + " is " + std::to_string(im->width()) + "x" +
                                std::to_string(im->height()) + ", intrinsics are " + K.to_string());
}

// Normal of the observed surface at (x, y) in the camera frame from central differences of the
// back-projected depth, facing the camera; the reversed viewing ray where it cannot be computed.
Eigen::Vector3f depth_normal(const DepthImage& D, const Intrinsics& K, int x, int y) {
  const Eigen::Vector3f ray = K.unproject(float(x), float(y), 1.0f).normalized();
  if (x <= 0 || y <= 0 || x >= D.width() - 1 || y >= D.height() - 1) return -ray;
  const float zl = D(x - 1, y), zr = D(x + 1, y), zu = D(x, y - 1), zd = D(x, y + 1);
  if (!(zl > 0 && zr > 0 && zu > 0 && zd > 0)) return -ray;
  const Eigen::Vector3f l = K.unproject(float(x - 1), float(y), zl), r = K.unproject(float(x + 1), float(y), zr);
  const Eigen::Vector3f u = K.unproject(float(x), float(y - 1), zu), d = K.unproject(float(x), float(y + 1), zd);
  Eigen::Vector3f n = (r - l).cross(d - u);
  if (!(n.norm() > 0)) return -ray;
  n.normalize();
  return n.dot(ray) > 0 ? Eigen::Vector3f(-n) : n;
}

// sqrt(mean squared distance to the 3 nearest other points), neighbours beyond `cap` counted as cap.
std::vector<float> knn3_scale(std::span<const Eigen::Vector3f> pts, float cap) {
  auto key = [cap](const Eigen::Vector3f& p) {
    const Eigen::Vector3i c = (p / cap).array().floor().cast<int>();
    return (uint64_t(uint32_t(c.x()) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(c.y()) & 0x1FFFFF) << 21) |
           uint64_t(uint32_t(c.z()) & 0x1FFFFF);
  };
  std::unordered_map<uint64_t, std::vector<int32_t>> grid;
  grid.reserve(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) grid[key(pts[i])].push_back(int32_t(i));
  std::vector<float> out(pts.size());
  const float cap2 = cap * cap;
  for (size_t i = 0; i < pts.size(); ++i) {
    std::array<float, 3> best = {cap2, cap2, cap2};  // ascending
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = grid.find(key(pts[i] + Eigen::Vector3f(float(dx), float(dy), float(dz)) * cap));
          if (it == grid.end()) continue;
          for (int32_t j : it->second) {
            if (size_t(j) == i) continue;
            const float d2 = (pts[size_t(j)] - pts[i]).squaredNorm();
            if (d2 >= best[2]) continue;
            best[2] = d2;
            std::sort(best.begin(), best.end());
          }
        }
    out[i] = std::sqrt((best[0] + best[1] + best[2]) / 3.0f);
  }
  return out;
}

}  // namespace

void DensifyParams::validate() const {
  auto check = [](bool ok, const char* name, float v) {
    if (!ok) throw std::invalid_argument(std::string("DensifyParams: bad ") + name + " = " + std::to_string(v));
  };
  check(base_error >= 0, "base_error", base_error);
  check(base_weight > 0, "base_weight", base_weight);
  check(reflection_error >= 0, "reflection_error", reflection_error);
  check(variance >= 0, "variance", variance);
  check(reflection_weight > 0, "reflection_weight", reflection_weight);
  check(sample_ratio >= 0 && sample_ratio <= 1, "sample_ratio", sample_ratio);
  check(reflection_samples >= 1, "reflection_samples", float(reflection_samples));
  check(reflection_near >= 0 && reflection_far >= reflection_near, "reflection_near/far", reflection_near);
  check(max_init_scale > 0, "max_init_scale", max_init_scale);
  check(base_min_init_scale > 0 && base_min_init_scale <= max_init_scale, "base_min_init_scale", base_min_init_scale);
  check(reflection_max_init_scale > 0, "reflection_max_init_scale", reflection_max_init_scale);
  check(reflection_min_init_scale > 0 && reflection_min_init_scale <= reflection_max_init_scale,
        "reflection_min_init_scale", reflection_min_init_scale);
  check(flatten > 0 && flatten <= 1, "flatten", flatten);
  check(init_opacity > 0 && init_opacity < 1, "init_opacity", init_opacity);
  check(reflection_sample_opacity >= 0 && reflection_sample_opacity < 1, "reflection_sample_opacity",
        reflection_sample_opacity);
}

float DensifyParams::reflection_sample_alpha() const {
  if (reflection_sample_opacity > 0) return reflection_sample_opacity;
  return 1.0f - std::pow(1.0f - init_opacity, 1.0f / float(reflection_samples));
}

GaussianHost init_gaussians(std::span<const Eigen::Vector3f> points, std::span<const Eigen::Vector3f> normals,
                            std::span<const Color> colors, std::span<const int32_t> plane_ids,
                            std::span<const float> opacities, const DensifyParams& params, float min_init_scale,
                            float max_init_scale, int sh_degree) {
  const size_t n = points.size();
  if (normals.size() != n || colors.size() != n || plane_ids.size() != n || opacities.size() != n)
    throw std::invalid_argument("init_gaussians: points, normals, colours, plane ids and opacities differ in length");
  for (const float o : opacities)
    if (!(o > 0.0f && o < 1.0f))
      throw std::invalid_argument("init_gaussians: opacity " + std::to_string(o) + " is outside (0, 1)");
  GaussianHost h(sh_degree);
  h.resize(n);
  const std::vector<float> s = knn3_scale(points, max_init_scale);
  const int K = h.sh_coeffs();
  for (size_t i = 0; i < n; ++i) {
    const float si = std::clamp(s[i], min_init_scale, max_init_scale);
    h.means[i] = points[i];
    h.log_scales[i] = Eigen::Vector3f(std::log(si), std::log(si), std::log(si * params.flatten));
    const Eigen::Quaternionf q = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), normals[i]);
    h.quats[i] = Eigen::Vector4f(q.w(), q.x(), q.y(), q.z());
    h.logit_opacities[i] = std::log(opacities[i] / (1.0f - opacities[i]));
    h.sh[i * size_t(K)] = (colors[i] - Color::Constant(0.5f)) / kShC0;
    h.plane_ids[i] = plane_ids[i];
  }
  return h;
}

GaussianHost densify_base(const DensifyView& v, const DensifyParams& p, int sh_degree, uint64_t seed,
                          std::span<const ReflectivePlane> reflective) {
  p.validate();
  check_image(v.C_gt, v.K, "C_gt");
  check_image(v.D_gt, v.K, "D_gt");
  check_image(v.C, v.K, "C");
  check_image(v.W_b, v.K, "W_b");
  const bool leave = p.base_leaves_reflections && !reflective.empty();
  std::unordered_set<int32_t> reflective_ids;
  if (leave) {
    check_image(v.R, v.K, "R");
    if (p.reflection_variance_gate) check_image(v.C_var, v.K, "C_var");
    check_image(v.I, v.K, "I");
    for (const ReflectivePlane& pl : reflective) reflective_ids.insert(pl.id);
  }
  std::vector<Eigen::Vector3f> pts, nrm;
  std::vector<Color> col;
  const Eigen::Matrix3f R_wc = v.T_wc.linear();
  for (int y = 0; y < v.K.height; ++y)
    for (int x = 0; x < v.K.width; ++x) {
      const float z = (*v.D_gt)(x, y);
      if (!(z > 0)) continue;
      if (!(color_error((*v.C_gt)(x, y), (*v.C)(x, y)) > p.base_error && (*v.W_b)(x, y) < p.base_weight)) continue;
      if (leave && (*v.R)(x, y) != 0 && (!p.reflection_variance_gate || (*v.C_var)(x, y) > p.variance) &&
          reflective_ids.count((*v.I)(x, y)) > 0)
        continue;
      if (!(pixel_uniform(seed, int64_t(y) * v.K.width + x) < p.sample_ratio)) continue;
      pts.push_back(v.T_wc * v.K.unproject(float(x), float(y), z));
      nrm.push_back(R_wc * depth_normal(*v.D_gt, v.K, x, y));
      col.push_back((*v.C_gt)(x, y));
    }
  const std::vector<int32_t> ids(pts.size(), 0);
  const std::vector<float> opacities(pts.size(), p.init_opacity);
  return init_gaussians(pts, nrm, col, ids, opacities, p, p.base_min_init_scale, p.max_init_scale, sh_degree);
}

GaussianHost densify_reflection(const DensifyView& v, std::span<const ReflectivePlane> planes, const DensifyParams& p,
                                int sh_degree, uint64_t seed) {
  p.validate();
  check_image(v.C_gt, v.K, "C_gt");
  check_image(v.C, v.K, "C");
  check_image(v.C_b, v.K, "C_b");
  check_image(v.W_r, v.K, "W_r");
  check_image(v.R, v.K, "R");
  if (p.reflection_variance_gate) check_image(v.C_var, v.K, "C_var");
  check_image(v.I, v.K, "I");
  std::unordered_map<int32_t, Eigen::Vector4f> by_id;
  for (const ReflectivePlane& pl : planes) {
    const float len = pl.plane.head<3>().norm();
    if (!(len > 0)) throw std::invalid_argument("densify_reflection: plane " + std::to_string(pl.id) + " has a zero normal");
    by_id[pl.id] = pl.plane / len;
  }
  std::vector<Eigen::Vector3f> pts, nrm;
  std::vector<Color> col;
  std::vector<int32_t> ids;
  // One of the S samples along a ray: the sample opacity (together as opaque as one new Gaussian);
  // a Gaussian at the mirrored surface: the base's initial opacity.
  std::vector<float> opacities;
  const float sample_alpha = p.reflection_sample_alpha();
  const Eigen::Vector3f o = v.T_wc.translation();
  const Eigen::Matrix3f R_wc = v.T_wc.linear();
  const int S = p.reflection_samples;
  const bool mirrored = p.reflection_mirrored_depth && v.virtual_depth != nullptr;
  if (mirrored) check_image(v.virtual_depth, v.K, "virtual_depth");
  // Pixels left after each test, in order (the debug log shows where candidates are lost).
  int64_t on_plane = 0, masked = 0, wrong = 0, varying = 0, uncovered = 0, sampled = 0, at_mirrored = 0;
  for (int y = 0; y < v.K.height; ++y)
    for (int x = 0; x < v.K.width; ++x) {
      const int32_t id = (*v.I)(x, y);
      const auto it = id > 0 ? by_id.find(id) : by_id.end();
      if (it == by_id.end()) continue;
      ++on_plane;
      if ((*v.R)(x, y) == 0) continue;
      ++masked;
      if (!(color_error((*v.C_gt)(x, y), (*v.C)(x, y)) > p.reflection_error)) continue;
      ++wrong;
      if (p.reflection_variance_gate && !((*v.C_var)(x, y) > p.variance)) continue;
      ++varying;
      if (!((*v.W_r)(x, y) < p.reflection_weight)) continue;
      ++uncovered;
      if (!(pixel_uniform(seed, int64_t(y) * v.K.width + x) < p.sample_ratio)) continue;
      ++sampled;
      const Eigen::Vector3f dir = (R_wc * v.K.unproject(float(x), float(y), 1.0f)).normalized();
      const Eigen::Vector3f n = it->second.head<3>();
      const float denom = n.dot(dir);
      if (std::abs(denom) < 1e-6f) continue;
      const float t = -(n.dot(o) + it->second.w()) / denom;
      if (!(t > 0)) continue;
      const Eigen::Vector3f hit = o + t * dir;
      const Color c = p.reflection_residual_color ? Color(((*v.C_gt)(x, y) - (*v.C_b)(x, y)).cwiseMax(0.0f))
                                                  : Color((*v.C_gt)(x, y));
      if (mirrored) {
        // One Gaussian at the mirrored surface when it lies behind the plane (the camera's
        // side of the plane has the opposite sign).
        const float z = (*v.virtual_depth)(x, y);
        const Eigen::Vector3f X = v.T_wc * v.K.unproject(float(x), float(y), z);
        const float side_cam = n.dot(o) + it->second.w(), side_X = n.dot(X) + it->second.w();
        if (z > 0 && side_cam * side_X < 0) {
          pts.push_back(X);
          nrm.push_back(n);
          col.push_back(c);
          ids.push_back(id);
          opacities.push_back(p.init_opacity);
          ++at_mirrored;
          continue;
        }
      }
      for (int j = 0; j < S; ++j) {
        const float s = S == 1 ? p.reflection_near
                               : p.reflection_near + (p.reflection_far - p.reflection_near) * float(j) / float(S - 1);
        pts.push_back(hit + s * dir);
        nrm.push_back(n);
        col.push_back(c);
        ids.push_back(id);
        opacities.push_back(sample_alpha);
      }
    }
  spdlog::debug("densify_reflection: {} reflective plane(s); pixels on them {}, with R = 1 {}, error > {} {}, "
                "C_var > {} {}, W_r < {} {}, sampled {} ({} at the mirrored surface)",
                planes.size(), on_plane, masked, p.reflection_error, wrong, p.variance, varying, p.reflection_weight,
                uncovered, sampled, at_mirrored);
  return init_gaussians(pts, nrm, col, ids, opacities, p, p.reflection_min_init_scale, p.reflection_max_init_scale,
                        sh_degree);
}

}  // namespace rrg
