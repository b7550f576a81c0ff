#include "core/synth/bvh.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace rrg::synth {

namespace {
constexpr int kLeafSize = 2;  // largest leaf the SAH may choose
}  // namespace

void Bvh::build(std::span<const Aabb> bounds, std::span<const int> ids) {
  if (bounds.size() != ids.size()) throw std::invalid_argument("Bvh::build: bounds and ids differ in size");
  if (bounds.size() > 30000) throw std::invalid_argument("Bvh::build: too many primitives");
  nodes_.clear();
  order_.clear();
  if (bounds.empty()) return;
  std::vector<int> items(bounds.size());
  std::iota(items.begin(), items.end(), 0);
  nodes_.reserve(2 * bounds.size());
  nodes_.emplace_back();
  build_node(0, items, bounds, 0, int(items.size()));
  order_.resize(items.size());
  for (size_t i = 0; i < items.size(); ++i) order_[i] = ids[size_t(items[i])];
}

namespace {
float half_area(const Aabb& b) {
  const Eigen::Vector3f e = (b.hi - b.lo).cwiseMax(0.0f);
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}
}  // namespace

void Bvh::build_node(int slot, std::vector<int>& items, std::span<const Aabb> bounds, int begin, int end) {
  Aabb box;
  for (int i = begin; i < end; ++i) box.grow(bounds[size_t(items[size_t(i)])]);
  nodes_[size_t(slot)].box = box;
  const int n = end - begin;
  // Surface area heuristic over every split of the centroid order on each axis (scenes have at
  // most a few hundred primitives, so the exhaustive O(n^2 log n) search is cheap).
  float best_cost = INFINITY;
  int best_axis = -1, best_split = 0;
  std::vector<float> left_area(size_t(n) + 1);
  for (int axis = 0; axis < 3 && n > 1; ++axis) {
    auto by_centre = [&](int a, int b) {
      const float ca = bounds[size_t(a)].centre()[axis], cb = bounds[size_t(b)].centre()[axis];
      return ca < cb || (ca == cb && a < b);  // a total order keeps the build deterministic
    };
    std::sort(items.begin() + begin, items.begin() + end, by_centre);
    Aabb acc;
    for (int i = 0; i < n; ++i) {
      acc.grow(bounds[size_t(items[size_t(begin + i)])]);
      left_area[size_t(i + 1)] = half_area(acc);
    }
    acc = Aabb{};
    for (int i = n - 1; i >= 1; --i) {
      acc.grow(bounds[size_t(items[size_t(begin + i)])]);
      const float cost = left_area[size_t(i)] * float(i) + half_area(acc) * float(n - i);
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_split = i;
      }
    }
  }
  const float leaf_cost = half_area(box) * float(n);
  if (n <= kLeafSize && (n == 1 || best_cost + half_area(box) * 0.5f >= leaf_cost)) best_axis = -1;
  if (best_axis < 0) {
    nodes_[size_t(slot)].first = begin;
    nodes_[size_t(slot)].count = int16_t(n);
    return;
  }
  std::sort(items.begin() + begin, items.begin() + end, [&](int a, int b) {
    const float ca = bounds[size_t(a)].centre()[best_axis], cb = bounds[size_t(b)].centre()[best_axis];
    return ca < cb || (ca == cb && a < b);
  });
  const int mid = begin + best_split;
  const int left = int(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[size_t(slot)].first = left;
  nodes_[size_t(slot)].axis = int16_t(best_axis);
  build_node(left, items, bounds, begin, mid);
  build_node(left + 1, items, bounds, mid, end);
}

}  // namespace rrg::synth
