#include "core/synth/renderer.h"

#include "core/synth/hash.h"
#include "core/synth/shading.h"

#include <omp.h>

#include <array>
#include <stdexcept>

namespace rrg::synth {

using Eigen::Vector2f;
using Eigen::Vector3f;

namespace {

constexpr float kRayEps = 1e-4f;  // metres: secondary ray origins are pushed off the surface
constexpr float kTwoPi = 6.28318531f;

// Display mapping of the renderer: tone_map() (shading.h) through a table over s = sqrt(x), where
// x^(1/2.2) = s^(2/2.2) is nearly linear: linear interpolation stays within 1e-4 of the exact curve
// (a fortieth of an 8-bit step).
class ToneCurve {
 public:
  ToneCurve() {
    for (int i = 0; i <= kSize; ++i) table_[size_t(i)] = std::pow(float(i) / kSize, 2.0f / 2.2f);
  }
  Color operator()(const Color& c, float exposure) const {
    return {map(c.x(), exposure), map(c.y(), exposure), map(c.z(), exposure)};
  }

 private:
  static constexpr int kSize = 1024;
  float map(float linear, float exposure) const {
    const float x = 1.0f - std::exp(-exposure * std::max(linear, 0.0f));
    const float f = std::sqrt(x) * kSize;
    const int i = std::min(int(f), kSize - 1);
    return table_[size_t(i)] + (table_[size_t(i) + 1] - table_[size_t(i)]) * (f - float(i));
  }
  std::array<float, kSize + 1> table_{};
};

struct SurfacePoint {
  Vector3f x, n;  // world hit point; unit normal facing the incoming ray
  uint32_t cell_key = 0;  // hash of (primitive, face, surface coordinates quantised to jitter_cell)
  const Material* material = nullptr;
  Color albedo;
};

SurfacePoint surface(const Scene& scene, const RayHit& hit, const Vector3f& o, const Vector3f& d, float cell) {
  const Primitive& p = scene.primitives[size_t(hit.prim)];
  SurfacePoint s;
  s.x = o + hit.t * d;
  Vector2f uv, size;
  surface_at(p, hit.face, s.x, s.n, uv, size);
  if (s.n.dot(d) > 0.0f) s.n = -s.n;  // back side of a rectangle
  s.material = &scene.materials[p.material[size_t(hit.face)]];
  s.albedo = eval_texture(s.material->texture, uv, size, p.seed);
  // In-surface coordinates, not x itself: x's offset along the normal is rounding noise and a
  // plane such as the floor (z = 0) would sit on a cell boundary.
  s.cell_key = hash4(uint32_t(hit.prim) * 8u + uint32_t(hit.face), quantise(uv.x(), cell), quantise(uv.y(), cell), 0x7e11u);
  return s;
}

// Diffuse irradiance at x with normal n: ambient sky-ish term plus soft point lights.
Color irradiance(const Scene& scene, const Vector3f& x, const Vector3f& n, bool shadows) {
  Color e = scene.ambient * (0.8f + 0.2f * n.z());
  const Vector3f x_off = x + n * kRayEps;
  for (const PointLight& light : scene.lights) {
    const Vector3f l = light.position - x;
    const float d2 = l.squaredNorm();
    const float w = wrapped_lambert(n.dot(l) / std::sqrt(d2));
    if (w <= 0.0f) continue;
    if (shadows && scene.occluded(x_off, light.position - x_off, 0.0f, 1.0f)) continue;
    e += light.intensity * (w / (1.0f + d2 / (light.falloff * light.falloff)));
  }
  return e;
}

// Unit vectors t1, t2 perpendicular to unit r.
void basis(const Vector3f& r, Vector3f& t1, Vector3f& t2) {
  const Vector3f a = std::abs(r.x()) < 0.9f ? Vector3f::UnitX() : Vector3f::UnitY();
  t1 = r.cross(a).normalized();
  t2 = r.cross(t1);
}

Color shade(const Scene& scene, const SurfacePoint& s, const Vector3f& d, const RenderParams& params,
            int bounce);

Color trace(const Scene& scene, const Vector3f& o, const Vector3f& d, const RenderParams& params, int bounce) {
  RayHit hit;
  if (!scene.intersect(o, d, 0.0f, INFINITY, hit)) return Color::Zero();
  return shade(scene, surface(scene, hit, o, d, params.jitter_cell), d, params, bounce);
}

// L = (1 - F) (albedo * E + emission) + F * L_reflected, F = Schlick(F0, cos θ).
Color shade(const Scene& scene, const SurfacePoint& s, const Vector3f& d, const RenderParams& params,
            int bounce) {
  const Material& m = *s.material;
  const Color direct = s.albedo.cwiseProduct(irradiance(scene, s.x, s.n, params.shadows && bounce == 0)) + m.emission;
  if (m.f0 <= 0.0f || bounce >= params.max_bounces) return direct;
  const Vector3f dn = d.normalized();
  const float cos_i = std::clamp(-dn.dot(s.n), 0.0f, 1.0f);
  const float F = fresnel_schlick(m.f0, cos_i);
  const Vector3f r = dn + 2.0f * cos_i * s.n;
  const Vector3f o = s.x + s.n * kRayEps;
  Color reflected = Color::Zero();
  const int k_count = (m.roughness > 0.0f && bounce == 0) ? std::max(1, params.rough_samples) : 1;
  if (k_count == 1) {
    reflected = trace(scene, o, r, params, bounce + 1);
  } else {
    // Jitter keyed on the quantised surface point only: the same surface point blurs the same
    // way from every view and in every frame.
    const uint32_t key = s.cell_key;
    Vector3f t1, t2;
    basis(r, t1, t2);
    for (int k = 0; k < k_count; ++k) {
      const float u1 = unit_float(hash3(key, uint32_t(k), 1u)), u2 = unit_float(hash3(key, uint32_t(k), 2u));
      const float phi = kTwoPi * (float(k) + u1) / float(k_count);  // stratified in angle
      const float rho = m.roughness * std::sqrt(u2);
      Vector3f dir = r + rho * (std::cos(phi) * t1 + std::sin(phi) * t2);
      const float below = dir.dot(s.n);
      if (below <= 0.0f) dir -= (2.0f * below - 1e-3f) * s.n;  // fold back above the surface
      reflected += trace(scene, o, dir, params, bounce + 1);
    }
    reflected /= float(k_count);
  }
  return (1.0f - F) * direct + F * reflected;
}

}  // namespace

Color trace_radiance(const Scene& scene, const Vector3f& o, const Vector3f& d, const RenderParams& params,
                     int bounce) {
  return trace(scene, o, d, params, bounce);
}

RenderOutput render_view(const Scene& scene, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                         const RenderParams& params) {
  if (!K.valid()) throw std::invalid_argument("render_view: invalid intrinsics " + K.to_string());
  if (!scene.finalized()) throw std::invalid_argument("render_view: scene '" + scene.name + "' is not finalized");
  const int w = K.width, h = K.height;
  RenderOutput out{ColorImage(w, h, Color::Zero()), DepthImage(w, h, 0.0f), LabelImage(w, h, 0),
                   LabelImage(w, h, 0), MaskImage(w, h, 0), Image<uint16_t>(w, h, 0)};
  const Eigen::Matrix3f R = T_wc.linear();
  const Vector3f o = T_wc.translation();
  const int threads = params.threads > 0 ? params.threads : omp_get_max_threads();
  static const ToneCurve tone_curve;

#pragma omp parallel for schedule(dynamic, 2) num_threads(threads)
  for (int v = 0; v < h; ++v) {
    const float y = (float(v) - K.cy) / K.fy;
    for (int u = 0; u < w; ++u) {
      // Camera ray with z = 1: the hit parameter t is the z-depth directly.
      const Vector3f d = R * Vector3f((float(u) - K.cx) / K.fx, y, 1.0f);
      RayHit hit;
      if (!scene.intersect(o, d, 0.0f, INFINITY, hit)) continue;
      const Primitive& p = scene.primitives[size_t(hit.prim)];
      const size_t f = size_t(hit.face);
      const SurfacePoint s = surface(scene, hit, o, d, params.jitter_cell);
      out.color(u, v) = tone_curve(shade(scene, s, d, params, 0), scene.exposure);
      out.depth(u, v) = hit.t;
      if (params.virtual_mirror_depth && s.material->f0 > params.mirror_f0) {
        // The reflected ray has |d|, so its hit parameter adds to the z-depth as the first one's.
        const Vector3f r = d - 2.0f * d.dot(s.n) * s.n;
        RayHit mirrored;
        out.depth(u, v) = scene.intersect(s.x + s.n * kRayEps, r, 0.0f, INFINITY, mirrored) ? hit.t + mirrored.t : 0.0f;
      }
      out.labels(u, v) = uint16_t(p.category[f]);
      out.planes(u, v) = p.plane[f];
      out.reflective(u, v) = s.material->f0 > 0.0f ? 1 : 0;
      out.material(u, v) = uint16_t(p.material[f] + 1);
    }
  }
  return out;
}

}  // namespace rrg::synth
