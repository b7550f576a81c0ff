#include "core/synth/scene.h"

#include <stdexcept>

namespace rrg::synth {

using Eigen::Vector3f;

namespace {
Vector3f inverse_direction(const Vector3f& d) { return {1.0f / d.x(), 1.0f / d.y(), 1.0f / d.z()}; }
}  // namespace

void Scene::finalize() {
  room_ = -1;
  planes_.clear();
  std::vector<Aabb> bounds;
  std::vector<int> ids;
  for (size_t i = 0; i < primitives.size(); ++i) {
    Primitive& p = primitives[i];
    const std::string what = "scene '" + name + "': primitive " + std::to_string(i) + " '" + p.name + "'";
    if (!(p.half.minCoeff() >= 0.0f) || p.half.x() <= 0.0f || p.half.y() <= 0.0f)
      throw std::invalid_argument(what + " has a non-positive size");
    if (p.kind != PrimitiveKind::Rect && !(p.half.z() > 0.0f))
      throw std::invalid_argument(what + " has a non-positive size");
    if (!(p.R * p.R.transpose()).isIdentity(1e-4f)) throw std::invalid_argument(what + " has a non-rotation R");
    p.identity_R = p.R == Eigen::Matrix3f::Identity();
    const auto used = faces_used(p.kind);
    for (int f = 0; f < 6; ++f) {
      if (!used[size_t(f)]) continue;
      if (p.material[size_t(f)] >= materials.size())
        throw std::invalid_argument(what + " uses an unknown material " + std::to_string(p.material[size_t(f)]));
      p.plane[size_t(f)] = 0;
      if (!face_is_planar(p.kind, f)) continue;
      PlaneInfo plane;
      if (planes_.size() >= 65535) throw std::invalid_argument("scene '" + name + "': too many planes");
      plane.id = uint16_t(planes_.size() + 1);
      const std::string suffix = face_suffix(p.kind, f);
      plane.name = p.kind == PrimitiveKind::Room ? suffix : suffix.empty() ? p.name : p.name + "_" + suffix;
      face_plane(p, f, plane.normal, plane.offset);
      plane.reflective = materials[p.material[size_t(f)]].f0 > 0.0f;
      plane.category = p.category[size_t(f)];
      p.plane[size_t(f)] = plane.id;
      planes_.push_back(plane);
    }
    if (p.kind == PrimitiveKind::Room) {
      if (room_ >= 0) throw std::invalid_argument("scene '" + name + "' has two rooms");
      room_ = int(i);
    } else {
      bounds.push_back(primitive_bounds(p));
      ids.push_back(int(i));
    }
  }
  for (const Material& m : materials)
    if (!(m.f0 >= 0.0f && m.f0 <= 1.0f) || !(m.roughness >= 0.0f))
      throw std::invalid_argument("scene '" + name + "': material '" + m.name + "' has F0 outside [0,1] or negative roughness");
  bvh_.build(bounds, ids);
  finalized_ = true;
}

bool Scene::intersect(const Vector3f& o, const Vector3f& d, float tmin, float tmax, RayHit& hit) const {
  float t_best = tmax;
  int face = 0;
  bool found = false;
  if (room_ >= 0 && intersect_primitive(primitives[size_t(room_)], o, d, tmin, t_best, face)) {
    hit.prim = room_;
    hit.face = face;
    found = true;
  }
  bvh_.traverse(o, inverse_direction(d), tmin, t_best, [&](int id, float& t_max) {
    if (intersect_primitive(primitives[size_t(id)], o, d, tmin, t_max, face)) {
      hit.prim = id;
      hit.face = face;
      found = true;
    }
    return false;
  });
  hit.t = t_best;
  return found;
}

bool Scene::occluded(const Vector3f& o, const Vector3f& d, float tmin, float tmax) const {
  float t_best = tmax;
  int face = 0;
  bool found = false;
  bvh_.traverse(o, inverse_direction(d), tmin, t_best, [&](int id, float& t_max) {
    found = intersect_primitive(primitives[size_t(id)], o, d, tmin, t_max, face);
    return found;
  });
  if (!found && room_ >= 0) found = intersect_primitive(primitives[size_t(room_)], o, d, tmin, t_best, face);
  return found;
}

bool Scene::is_free(const Vector3f& p, float margin) const {
  for (size_t i = 0; i < primitives.size(); ++i) {
    const bool inside = point_inside(primitives[i], p, margin);
    if (int(i) == room_ ? !inside : inside) return false;
  }
  return true;
}

std::vector<CategoryInfo> Scene::categories() const {
  std::vector<CategoryInfo> out;
  std::vector<int> state(size_t(Category::Count), 0);  // 0 absent, 1 matte, 2 reflective
  for (const Primitive& p : primitives) {
    const auto used = faces_used(p.kind);
    for (int f = 0; f < 6; ++f) {
      if (!used[size_t(f)] || p.category[size_t(f)] == Category::None) continue;
      int& s = state[size_t(p.category[size_t(f)])];
      s = std::max(s, materials[p.material[size_t(f)]].f0 > 0.0f ? 2 : 1);
    }
  }
  for (size_t c = 1; c < state.size(); ++c)
    if (state[c] > 0) out.push_back({Category(c), state[c] == 2});
  return out;
}

Aabb Scene::bounds() const {
  Aabb box;
  for (const Primitive& p : primitives) box.grow(primitive_bounds(p));
  return box;
}

}  // namespace rrg::synth
