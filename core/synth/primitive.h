#pragma once
// Analytic scene primitives and their ray intersection. Every primitive lives in its own local
// frame (p_local = R * (p_world - center)); the room is an inward-facing box. Face indices follow
// the box: 0 -x, 1 +x, 2 -y, 3 +y, 4 -z (bottom), 5 +z (top). A rectangle is face 5 (normal +z);
// a sphere is face 0; a cylinder's side is face 0 and its caps faces 4 / 5. Curved faces (sphere,
// cylinder side) carry no plane id.
#include "core/synth/categories.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace rrg::synth {

enum class PrimitiveKind : uint8_t { Box, Room, Rect, Sphere, Cylinder };

struct Aabb {
  Eigen::Vector3f lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  void grow(const Aabb& o) { lo = lo.cwiseMin(o.lo); hi = hi.cwiseMax(o.hi); }
  void grow(const Eigen::Vector3f& p) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); }
  Eigen::Vector3f centre() const { return (lo + hi) * 0.5f; }
};

struct Primitive {
  PrimitiveKind kind = PrimitiveKind::Box;
  std::string name;                 // "coffee_table_top"; faces append "_top", "_xn", ...
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  Eigen::Matrix3f R = Eigen::Matrix3f::Identity();  // world -> local rotation (rows: local axes)
  Eigen::Vector3f half = Eigen::Vector3f::Ones();   // box: half extents; rect: (hx, hy, 0);
                                                    // sphere: (r, r, r); cylinder: (r, r, half height)
  std::array<uint16_t, 6> material{};  // per face, index into Scene::materials
  std::array<Category, 6> category{};  // per face
  std::array<uint16_t, 6> plane{};     // per face plane id (assigned by Scene::finalize), 0 = none
  uint32_t seed = 0;                   // texture variation
  bool identity_R = false;             // set by Scene::finalize: R is exactly I (skip the rotation)
};

// World-space bounds of a primitive.
Aabb primitive_bounds(const Primitive& p);
// True when face `face` of a primitive of this kind is planar (gets a plane id).
bool face_is_planar(PrimitiveKind kind, int face);
// Faces a primitive of this kind has (indices into the per-face arrays).
std::array<bool, 6> faces_used(PrimitiveKind kind);
// Short face suffix for plane names: "xn", "xp", "yn", "yp", "bottom", "top" (room: wall / floor ...).
std::string face_suffix(PrimitiveKind kind, int face);
// World plane n.x + b = 0 of a planar face (n points out of the solid; into the room for Room).
void face_plane(const Primitive& p, int face, Eigen::Vector3f& n, float& b);
// Signed distance-like test: true when world point q is inside the solid (expanded by margin).
// The room counts as inside when q is inside the room shrunk by margin.
bool point_inside(const Primitive& p, const Eigen::Vector3f& q, float margin);

// ---- intersection in the local frame (hot path, inline) -------------------------------------
// o, d: ray in the primitive's local frame (d need not be unit). On a hit with tmin <= t < t_best,
// sets t_best and face and returns true.

inline bool intersect_box_local(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                const Eigen::Vector3f& h, float tmin, float& t_best, int& face) {
  float tn = -INFINITY, tf = INFINITY;
  int fn = 0;
  for (int a = 0; a < 3; ++a) {
    const float inv = 1.0f / d[a];
    float t0 = (-h[a] - o[a]) * inv, t1 = (h[a] - o[a]) * inv;
    int f0 = 2 * a;  // entering through -h when d > 0
    if (t0 > t1) { std::swap(t0, t1); f0 = 2 * a + 1; }
    if (t0 > tn) { tn = t0; fn = f0; }
    if (t1 < tf) tf = t1;
  }
  if (tn > tf || tn < tmin || tn >= t_best) return false;  // solid: rays from inside pass
  t_best = tn;
  face = fn;
  return true;
}

inline bool intersect_room_local(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                 const Eigen::Vector3f& h, float tmin, float& t_best, int& face) {
  float tf = INFINITY;
  int ff = 0;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float inv = 1.0f / d[a];
    const float t1 = d[a] > 0.0f ? (h[a] - o[a]) * inv : (-h[a] - o[a]) * inv;
    if (t1 < tf) { tf = t1; ff = d[a] > 0.0f ? 2 * a + 1 : 2 * a; }
  }
  if (tf < tmin || tf >= t_best) return false;
  t_best = tf;
  face = ff;
  return true;
}

inline bool intersect_rect_local(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                 const Eigen::Vector3f& h, float tmin, float& t_best, int& face) {
  if (d.z() == 0.0f) return false;
  const float t = -o.z() / d.z();
  if (t < tmin || t >= t_best) return false;
  const float x = o.x() + t * d.x(), y = o.y() + t * d.y();
  if (std::abs(x) > h.x() || std::abs(y) > h.y()) return false;
  t_best = t;
  face = 5;
  return true;
}

inline bool intersect_sphere_local(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float r,
                                   float tmin, float& t_best, int& face) {
  const float a = d.dot(d), b = o.dot(d), c = o.dot(o) - r * r;
  const float disc = b * b - a * c;
  if (disc < 0.0f) return false;
  const float t = (-b - std::sqrt(disc)) / a;
  if (t < tmin || t >= t_best) return false;
  t_best = t;
  face = 0;
  return true;
}

inline bool intersect_cylinder_local(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float r,
                                     float hz, float tmin, float& t_best, int& face) {
  bool hit = false;
  const float a = d.x() * d.x() + d.y() * d.y();
  if (a > 0.0f) {
    const float b = o.x() * d.x() + o.y() * d.y(), c = o.x() * o.x() + o.y() * o.y() - r * r;
    const float disc = b * b - a * c;
    if (disc >= 0.0f) {
      const float t = (-b - std::sqrt(disc)) / a;
      const float z = o.z() + t * d.z();
      if (t >= tmin && t < t_best && std::abs(z) <= hz) { t_best = t; face = 0; hit = true; }
    }
  }
  if (d.z() != 0.0f) {
    const float zc = d.z() > 0.0f ? -hz : hz;  // the cap a ray can enter through
    const float t = (zc - o.z()) / d.z();
    if (t >= tmin && t < t_best) {
      const float x = o.x() + t * d.x(), y = o.y() + t * d.y();
      if (x * x + y * y <= r * r) { t_best = t; face = d.z() > 0.0f ? 4 : 5; hit = true; }
    }
  }
  return hit;
}

// Dispatch on the primitive kind; o_w, d_w are the world ray.
inline bool intersect_primitive(const Primitive& p, const Eigen::Vector3f& o_w,
                                const Eigen::Vector3f& d_w, float tmin, float& t_best, int& face) {
  Eigen::Vector3f o = o_w - p.center, d = d_w;
  if (!p.identity_R) {
    o = p.R * o;
    d = p.R * d;
  }
  switch (p.kind) {
    case PrimitiveKind::Box: return intersect_box_local(o, d, p.half, tmin, t_best, face);
    case PrimitiveKind::Room: return intersect_room_local(o, d, p.half, tmin, t_best, face);
    case PrimitiveKind::Rect: return intersect_rect_local(o, d, p.half, tmin, t_best, face);
    case PrimitiveKind::Sphere: return intersect_sphere_local(o, d, p.half.x(), tmin, t_best, face);
    case PrimitiveKind::Cylinder:
      return intersect_cylinder_local(o, d, p.half.x(), p.half.z(), tmin, t_best, face);
  }
  return false;
}

// Surface frame of a hit: world normal (outward; into the room for Room), face coordinates uv
// (metres from the face corner) and the face size, from the world hit point.
void surface_at(const Primitive& p, int face, const Eigen::Vector3f& x_world, Eigen::Vector3f& n_world,
                Eigen::Vector2f& uv, Eigen::Vector2f& face_size);

}  // namespace rrg::synth
