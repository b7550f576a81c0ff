#include "core/planes/plane_footprint.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rrg {

void Box2::extend(const Eigen::Vector2f& p) {
  if (empty) {
    min = max = p;
    empty = false;
  } else {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
}

void Box2::extend(const Box2& b) {
  if (b.empty) return;
  extend(b.min);
  extend(b.max);
}

float Box2::area() const { return empty ? 0.0f : (max - min).prod(); }

float box_iou(const Box2& a, const Box2& b) {
  if (a.empty || b.empty) return 0.0f;
  const Eigen::Vector2f lo = a.min.cwiseMax(b.min), hi = a.max.cwiseMin(b.max);
  if ((hi.array() <= lo.array()).any()) return 0.0f;
  const float inter = (hi - lo).prod();
  const float uni = a.area() + b.area() - inter;
  return uni > 0.0f ? inter / uni : 0.0f;
}

float box_gap(const Box2& a, const Box2& b) {
  if (a.empty || b.empty) return std::numeric_limits<float>::infinity();
  const Eigen::Vector2f gap = (a.min - b.max).cwiseMax(b.min - a.max).cwiseMax(0.0f);
  return gap.norm();
}

PlaneBasis PlaneBasis::from_plane(const Plane& plane, const Eigen::Vector3f& point_near) {
  PlaneBasis b;
  const Eigen::Vector3f& n = plane.n;
  b.origin = point_near - plane.signed_distance(point_near) * n;  // foot of the point on the plane
  // u: the world axis least aligned with n, made orthogonal to n.
  Eigen::Vector3f a = Eigen::Vector3f::UnitX();
  if (std::abs(n.y()) < std::abs(n(0)) && std::abs(n.y()) <= std::abs(n.z())) a = Eigen::Vector3f::UnitY();
  else if (std::abs(n.z()) < std::abs(n(0)) && std::abs(n.z()) < std::abs(n.y())) a = Eigen::Vector3f::UnitZ();
  b.u = (a - a.dot(n) * n).normalized();
  b.v = n.cross(b.u).normalized();
  return b;
}

Footprint::Footprint(const PlaneBasis& basis, float cell_size) : basis_(basis), cell_(cell_size) {
  if (!(cell_size > 0.0f)) throw std::invalid_argument("Footprint: cell size must be > 0");
}

void Footprint::add_points(std::span<const Eigen::Vector3f> points) {
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector2f q = basis_.project(p);
    cells_.insert(key(int(std::floor(q.x() / cell_)), int(std::floor(q.y() / cell_))));
    box_.extend(q);
  }
}

void Footprint::merge(const Footprint& other) {
  for (uint64_t k : other.cells_) {
    const int i = int(int32_t(uint32_t(k >> 32))), j = int(int32_t(uint32_t(k & 0xffffffffu)));
    const Eigen::Vector3f centre = other.basis_.origin + (float(i) + 0.5f) * other.cell_ * other.basis_.u +
                                   (float(j) + 0.5f) * other.cell_ * other.basis_.v;
    const Eigen::Vector2f q = basis_.project(centre);
    cells_.insert(key(int(std::floor(q.x() / cell_)), int(std::floor(q.y() / cell_))));
  }
  if (!other.box_.empty) {  // the other box's corners, re-projected
    const Box2& ob = other.box_;
    for (int c = 0; c < 4; ++c) {
      const float x = (c & 1) ? ob.max.x() : ob.min.x(), y = (c & 2) ? ob.max.y() : ob.min.y();
      box_.extend(basis_.project(other.basis_.origin + x * other.basis_.u + y * other.basis_.v));
    }
  }
}

bool Footprint::covers(const Eigen::Vector3f& p) const {
  const Eigen::Vector2f q = basis_.project(p) / cell_;
  const int i = int(std::floor(q.x())), j = int(std::floor(q.y()));
  for (int di = -1; di <= 1; ++di)
    for (int dj = -1; dj <= 1; ++dj)
      if (contains_cell(i + di, j + dj)) return true;
  return false;
}

float Footprint::overlap_ratio(const Footprint& other) const {
  if (other.cells_.empty()) return 0.0f;
  size_t hit = 0;
  for (uint64_t k : other.cells_) {
    const int i = int(int32_t(uint32_t(k >> 32))), j = int(int32_t(uint32_t(k & 0xffffffffu)));
    bool found = false;
    for (int dj = -1; dj <= 1 && !found; ++dj)
      for (int di = -1; di <= 1 && !found; ++di) found = contains_cell(i + di, j + dj);
    hit += found ? 1 : 0;
  }
  return float(hit) / float(other.cells_.size());
}

}  // namespace rrg
