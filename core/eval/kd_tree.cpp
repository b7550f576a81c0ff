#include "core/eval/kd_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace rrg::eval {
namespace {
constexpr size_t kLeafSize = 8;
// A cell is searched when its box distance is below best·(1 + slack): the slack absorbs float
// rounding between the box distance and a point distance, so no point is ever missed.
constexpr float kPruneSlack = 1e-5f;
}

KdTree::KdTree(std::vector<Eigen::Vector3f> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("KdTree: no points");
  if (points_.size() > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("KdTree: more than 2^32 points");
  for (size_t i = 0; i < points_.size(); ++i)
    if (!points_[i].allFinite()) throw std::invalid_argument("KdTree: point " + std::to_string(i) + " is not finite");
  original_.resize(points_.size());
  std::iota(original_.begin(), original_.end(), 0u);
  axis_.assign(points_.size(), 0);
  lower_.assign(points_.size(), Eigen::Vector3f::Zero());
  upper_.assign(points_.size(), Eigen::Vector3f::Zero());
  build(0, points_.size());
}

void KdTree::build(size_t lo, size_t hi) {
  if (hi - lo <= kLeafSize) return;
  Eigen::Vector3f lower = points_[lo], upper = points_[lo];
  for (size_t i = lo + 1; i < hi; ++i) {
    lower = lower.cwiseMin(points_[i]);
    upper = upper.cwiseMax(points_[i]);
  }
  int axis = 0;
  (upper - lower).maxCoeff(&axis);

  // Partition an index range, then apply it to points_ and original_ together.
  const size_t mid = lo + (hi - lo) / 2;
  lower_[mid] = lower;
  upper_[mid] = upper;
  std::vector<uint32_t> order(hi - lo);
  std::iota(order.begin(), order.end(), uint32_t(lo));
  std::nth_element(order.begin(), order.begin() + (mid - lo), order.end(),
                   [&](uint32_t a, uint32_t b) { return points_[a][axis] < points_[b][axis]; });
  std::vector<Eigen::Vector3f> p(hi - lo);
  std::vector<uint32_t> o(hi - lo);
  for (size_t k = 0; k < order.size(); ++k) {
    p[k] = points_[order[k]];
    o[k] = original_[order[k]];
  }
  std::copy(p.begin(), p.end(), points_.begin() + lo);
  std::copy(o.begin(), o.end(), original_.begin() + lo);
  axis_[mid] = uint8_t(axis);
  build(lo, mid);
  build(mid + 1, hi);
}

KdTree::Neighbor KdTree::nearest(const Eigen::Vector3f& q) const {
  Neighbor best{0, std::numeric_limits<float>::infinity()};
  search(0, points_.size(), q, box_distance_sq(0, points_.size(), q), best);
  best.index = original_[best.index];
  return best;
}

float KdTree::box_distance_sq(size_t lo, size_t hi, const Eigen::Vector3f& q) const {
  if (hi - lo <= kLeafSize) return 0.0f;  // leaves keep no box: their few points are checked directly
  const size_t mid = lo + (hi - lo) / 2;
  return ((lower_[mid] - q).cwiseMax(0.0f) + (q - upper_[mid]).cwiseMax(0.0f)).squaredNorm();
}

void KdTree::search(size_t lo, size_t hi, const Eigen::Vector3f& q, float box_sq, Neighbor& best) const {
  if (box_sq > best.distance_sq * (1.0f + kPruneSlack)) return;
  if (hi - lo <= kLeafSize) {
    for (size_t i = lo; i < hi; ++i) {
      const float d2 = (points_[i] - q).squaredNorm();
      if (d2 < best.distance_sq) best = {i, d2};
    }
    return;
  }
  const size_t mid = lo + (hi - lo) / 2;
  const float d2 = (points_[mid] - q).squaredNorm();
  if (d2 < best.distance_sq) best = {mid, d2};
  // [lo, mid) lies at or below the splitting point along the axis, [mid + 1, hi) at or above it:
  // the side q is on first, each child pruned by its own box.
  const float below = box_distance_sq(lo, mid, q), above = box_distance_sq(mid + 1, hi, q);
  if (q[axis_[mid]] < points_[mid][axis_[mid]]) {
    search(lo, mid, q, below, best);
    search(mid + 1, hi, q, above, best);
  } else {
    search(mid + 1, hi, q, above, best);
    search(lo, mid, q, below, best);
  }
}

}  // namespace rrg::eval
