#include "core/synth/primitive.h"

#include <algorithm>

namespace rrg::synth {

using Eigen::Vector2f;
using Eigen::Vector3f;

namespace {
constexpr float kPi = 3.14159265f;
// The two in-face axes of box face axis a, ordered so v is vertical on walls.
constexpr int kFaceAxes[3][2] = {{1, 2}, {0, 2}, {0, 1}};
}  // namespace

Aabb primitive_bounds(const Primitive& p) {
  Vector3f h = p.half;
  if (p.kind == PrimitiveKind::Rect) h.z() = 1e-4f;
  // |R^T| h: extent of the rotated box along each world axis.
  const Vector3f ext = p.R.transpose().cwiseAbs() * h;
  Aabb box;
  box.lo = p.center - ext;
  box.hi = p.center + ext;
  return box;
}

std::array<bool, 6> faces_used(PrimitiveKind kind) {
  switch (kind) {
    case PrimitiveKind::Box:
    case PrimitiveKind::Room: return {true, true, true, true, true, true};
    case PrimitiveKind::Rect: return {false, false, false, false, false, true};
    case PrimitiveKind::Sphere: return {true, false, false, false, false, false};
    case PrimitiveKind::Cylinder: return {true, false, false, false, true, true};
  }
  return {};
}

bool face_is_planar(PrimitiveKind kind, int face) {
  if (!faces_used(kind)[size_t(face)]) return false;
  if (kind == PrimitiveKind::Sphere) return false;
  if (kind == PrimitiveKind::Cylinder) return face != 0;
  return true;
}

std::string face_suffix(PrimitiveKind kind, int face) {
  if (kind == PrimitiveKind::Room) {
    static const char* kRoom[6] = {"wall_xn", "wall_xp", "wall_yn", "wall_yp", "floor", "ceiling"};
    return kRoom[face];
  }
  if (kind == PrimitiveKind::Rect) return "";
  if (kind == PrimitiveKind::Sphere || (kind == PrimitiveKind::Cylinder && face == 0)) return "side";
  static const char* kBox[6] = {"xn", "xp", "yn", "yp", "bottom", "top"};
  return kBox[face];
}

void face_plane(const Primitive& p, int face, Vector3f& n, float& b) {
  const int axis = face / 2;
  const float sign = (face & 1) ? 1.0f : -1.0f;
  Vector3f n_local = Vector3f::Zero();
  n_local[axis] = sign;
  Vector3f x_local = Vector3f::Zero();
  x_local[axis] = sign * p.half[axis];
  if (p.kind == PrimitiveKind::Rect) x_local.setZero();
  if (p.kind == PrimitiveKind::Room) n_local = -n_local;
  n = p.R.transpose() * n_local;
  const Vector3f x = p.R.transpose() * x_local + p.center;
  b = -n.dot(x) + 0.0f;  // + 0: no "-0" in planes.json
  n = n + Vector3f::Zero();
}

bool point_inside(const Primitive& p, const Vector3f& q, float margin) {
  const Vector3f l = p.R * (q - p.center);
  switch (p.kind) {
    case PrimitiveKind::Room:
      return (l.cwiseAbs() - p.half).maxCoeff() < -margin;
    case PrimitiveKind::Box:
    case PrimitiveKind::Rect: {
      const Vector3f d = l.cwiseAbs() - p.half;
      return d.maxCoeff() < margin && d.cwiseMax(0.0f).norm() < margin;
    }
    case PrimitiveKind::Sphere: return l.norm() < p.half.x() + margin;
    case PrimitiveKind::Cylinder: {
      const float dr = std::hypot(l.x(), l.y()) - p.half.x(), dz = std::abs(l.z()) - p.half.z();
      return std::max(dr, dz) < margin && Eigen::Vector2f(std::max(dr, 0.0f), std::max(dz, 0.0f)).norm() < margin;
    }
  }
  return false;
}

void surface_at(const Primitive& p, int face, const Vector3f& x_world, Vector3f& n_world,
                Vector2f& uv, Vector2f& face_size) {
  const Vector3f l = p.R * (x_world - p.center);
  Vector3f n_local = Vector3f::Zero();
  switch (p.kind) {
    case PrimitiveKind::Box:
    case PrimitiveKind::Room:
    case PrimitiveKind::Rect: {
      const int axis = face / 2, a1 = kFaceAxes[axis][0], a2 = kFaceAxes[axis][1];
      n_local[axis] = (face & 1) ? 1.0f : -1.0f;
      if (p.kind == PrimitiveKind::Room) n_local = -n_local;
      uv = {l[a1] + p.half[a1], l[a2] + p.half[a2]};
      face_size = {2.0f * p.half[a1], 2.0f * p.half[a2]};
      break;
    }
    case PrimitiveKind::Sphere: {
      const float r = p.half.x();
      n_local = l / r;
      const float phi = std::atan2(l.y(), l.x()), theta = std::acos(std::clamp(l.z() / r, -1.0f, 1.0f));
      uv = {(phi + kPi) * r, theta * r};
      face_size = {2.0f * kPi * r, kPi * r};
      break;
    }
    case PrimitiveKind::Cylinder: {
      const float r = p.half.x(), hz = p.half.z();
      if (face == 0) {
        n_local = Vector3f(l.x(), l.y(), 0.0f) / r;
        uv = {(std::atan2(l.y(), l.x()) + kPi) * r, l.z() + hz};
        face_size = {2.0f * kPi * r, 2.0f * hz};
      } else {
        n_local.z() = face == 5 ? 1.0f : -1.0f;
        uv = {l.x() + r, l.y() + r};
        face_size = {2.0f * r, 2.0f * r};
      }
      break;
    }
  }
  n_world = (p.R.transpose() * n_local).normalized();
}

}  // namespace rrg::synth
