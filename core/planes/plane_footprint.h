#pragma once
// The spatial footprint of a global plane (supplement, "Global Plane Maintenance"): occupied cells
// of a regular grid (cell 0.05 m) in a 2D orthonormal basis on the plane, and their axis-aligned
// bounding box. Association compares a local plane's points with a candidate's footprint through
// the cell overlap ratio (1-cell dilation), the bounding-box IoU and the bounding-box gap.
#include "core/planes/plane_types.h"

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <unordered_set>

namespace rrg {

struct PlaneStateIo;

struct Box2 {
  Eigen::Vector2f min{0, 0}, max{0, 0};  // inclusive metres in the plane basis
  bool empty = true;
  void extend(const Eigen::Vector2f& p);
  void extend(const Box2& b);
  float area() const;
};
float box_iou(const Box2& a, const Box2& b);  // 0 when either is empty
float box_gap(const Box2& a, const Box2& b);  // Euclidean gap between the boxes, 0 when they touch

// A 2D frame on a plane: origin o on the plane and unit axes u, v orthogonal to n.
struct PlaneBasis {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero(), u = Eigen::Vector3f::UnitX(), v = Eigen::Vector3f::UnitY();
  static PlaneBasis from_plane(const Plane& plane, const Eigen::Vector3f& point_near);
  Eigen::Vector2f project(const Eigen::Vector3f& p) const { return {u.dot(p - origin), v.dot(p - origin)}; }
};

class Footprint {
 public:
  Footprint() = default;
  Footprint(const PlaneBasis& basis, float cell_size);

  const PlaneBasis& basis() const { return basis_; }
  float cell_size() const { return cell_; }
  size_t cells() const { return cells_.size(); }
  const Box2& box() const { return box_; }
  bool contains_cell(int i, int j) const { return cells_.count(key(i, j)) > 0; }
  // Whether p (world frame, on or near the plane) falls in this footprint dilated by one cell.
  bool covers(const Eigen::Vector3f& p) const;

  // Projects points (world frame, on or near the plane) into the grid.
  void add_points(std::span<const Eigen::Vector3f> points);
  // Adds another footprint, re-projecting its cell centres into this basis.
  void merge(const Footprint& other);

  // Fraction of `other`'s cells that fall in this footprint dilated by one cell (8-neighbourhood).
  // `other` must share this basis (footprint_in(basis) builds one).
  float overlap_ratio(const Footprint& other) const;

  static uint64_t key(int i, int j) { return (uint64_t(uint32_t(i)) << 32) | uint32_t(j); }
  const std::unordered_set<uint64_t>& cell_keys() const { return cells_; }

 private:
  friend struct PlaneStateIo;  // snapshots (plane_state_io.h)
  PlaneBasis basis_;
  float cell_ = 0.05f;
  std::unordered_set<uint64_t> cells_;
  Box2 box_;
};

}  // namespace rrg
