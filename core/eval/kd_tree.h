#pragma once
// A static 3-D kd-tree for exact nearest-neighbour queries (mesh accuracy / completion). Implicit
// layout: the points are reordered so that every range [lo, hi) has its splitting point at its
// middle, split on the axis of the range's largest extent; ranges of ≤ 8 points are leaves.
// The search keeps the query's per-axis offset to the current cell's box (Arya & Mount's
// incremental distance), so a cell is skipped when its whole box is farther than the best point:
// essential for queries off the sampled surface (every cell is then at least that far).
// Queries are const and thread-safe.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rrg::eval {

class KdTree {
 public:
  struct Neighbor {
    size_t index = 0;          // into the points given to the constructor
    float distance_sq = 0.0f;  // squared Euclidean distance, m²
  };

  // Throws std::invalid_argument when there are no points or a point is not finite.
  explicit KdTree(std::vector<Eigen::Vector3f> points);

  size_t size() const { return points_.size(); }
  // The exact nearest point to q (ties: whichever the search meets first).
  Neighbor nearest(const Eigen::Vector3f& q) const;

 private:
  void build(size_t lo, size_t hi);
  // off: per-axis distance from q to the box of [lo, hi); box_sq = ‖off‖².
  void search(size_t lo, size_t hi, const Eigen::Vector3f& q, const Eigen::Vector3f& off, float box_sq,
              Neighbor& best) const;

  std::vector<Eigen::Vector3f> points_;  // reordered
  std::vector<uint32_t> original_;       // points_[i] was input point original_[i]
  std::vector<uint8_t> axis_;            // split axis of the range whose middle is i
  Eigen::Vector3f lower_, upper_;        // bounding box of all points
};

}  // namespace rrg::eval
