#pragma once
// A static 3-D kd-tree for exact nearest-neighbour queries (mesh accuracy / completion). Implicit
// layout: the points are reordered so that every range [lo, hi) has its splitting point at its
// middle, split on the axis of the range's largest extent; ranges of ≤ 8 points are leaves.
// Every inner range keeps the tight bounding box of its points, and the search skips a range
// whose box is farther than the best point so far. Tight boxes matter for queries far off the
// sampled surface (completion of unreconstructed regions, metres away): the half-spaces of the
// splitting planes bound a surface's points far more loosely than their own thin boxes, and with
// those bounds a query 1 m away visited most of a room's samples.
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
  // box_sq: squared distance from q to the box of [lo, hi) (0 when [lo, hi) is a leaf).
  void search(size_t lo, size_t hi, const Eigen::Vector3f& q, float box_sq, Neighbor& best) const;
  float box_distance_sq(size_t lo, size_t hi, const Eigen::Vector3f& q) const;

  std::vector<Eigen::Vector3f> points_;  // reordered
  std::vector<uint32_t> original_;       // points_[i] was input point original_[i]
  std::vector<uint8_t> axis_;            // split axis of the range whose middle is i
  std::vector<Eigen::Vector3f> lower_, upper_;  // tight box of the inner range whose middle is i
};

}  // namespace rrg::eval
