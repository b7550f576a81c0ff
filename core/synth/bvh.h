#pragma once
// Bounding volume hierarchy over primitive bounds: median split on the widest centroid axis,
// small leaves, front-to-back traversal with an explicit stack. Built once per scene.
#include "core/synth/primitive.h"

#include <cstdint>
#include <span>
#include <vector>

namespace rrg::synth {

struct BvhNode {
  Aabb box;
  int32_t first = 0;  // leaf: first index into Bvh::order; inner: index of the left child
  int16_t count = 0;  // > 0: leaf with `count` primitives
  int16_t axis = 0;   // inner: split axis (near child first when the ray goes +axis)
};

class Bvh {
 public:
  // Builds over the given bounds; ids[i] is reported for bounds[i].
  void build(std::span<const Aabb> bounds, std::span<const int> ids);
  bool empty() const { return nodes_.empty(); }
  size_t node_count() const { return nodes_.size(); }

  // Visits leaves whose box the ray (o, inv_d) enters before t_max, near first; visit(id, t_max)
  // may shrink t_max (closest hit) and returns true to stop the traversal (any hit).
  template <class Visit>
  void traverse(const Eigen::Vector3f& o, const Eigen::Vector3f& inv_d, float tmin, float& t_max,
                Visit&& visit) const;

 private:
  // Fills node `slot` from items[begin, end); children go to two consecutive new slots.
  void build_node(int slot, std::vector<int>& items, std::span<const Aabb> bounds, int begin, int end);
  std::vector<BvhNode> nodes_;
  std::vector<int> order_;  // primitive ids in leaf order
};

// Slab test of a box against a ray; true when it is entered within [tmin, tmax].
inline bool ray_box(const Aabb& b, const Eigen::Vector3f& o, const Eigen::Vector3f& inv_d, float tmin,
                    float tmax) {
  const Eigen::Vector3f t0 = (b.lo - o).cwiseProduct(inv_d), t1 = (b.hi - o).cwiseProduct(inv_d);
  const float tn = std::max(tmin, t0.cwiseMin(t1).maxCoeff());
  const float tf = std::min(tmax, t0.cwiseMax(t1).minCoeff());
  return tn <= tf;
}

template <class Visit>
void Bvh::traverse(const Eigen::Vector3f& o, const Eigen::Vector3f& inv_d, float tmin, float& t_max,
                   Visit&& visit) const {
  if (nodes_.empty()) return;
  int stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = nodes_[size_t(stack[--top])];
    if (!ray_box(node.box, o, inv_d, tmin, t_max)) continue;
    if (node.count > 0) {
      for (int i = 0; i < node.count; ++i)
        if (visit(order_[size_t(node.first + i)], t_max)) return;
      continue;
    }
    const bool positive = inv_d[node.axis] >= 0.0f;
    const int near_child = positive ? node.first : node.first + 1;
    stack[top++] = positive ? node.first + 1 : node.first;  // far child later
    stack[top++] = near_child;
  }
}

}  // namespace rrg::synth
