#include "core/tsdf/marching_cubes_table.h"

#include <stdexcept>
#include <vector>

namespace rrg::mc {
namespace {

Eigen::Vector3i corner_offset(int c) { return {c & 1, (c >> 1) & 1, c >> 2}; }

// Edge index joining two corners that differ in one coordinate.
int edge_between(int c0, int c1) {
  const Eigen::Vector3i a = corner_offset(c0), b = corner_offset(c1);
  const Eigen::Vector3i lo = a.cwiseMin(b);
  for (int axis = 0; axis < 3; ++axis) {
    if (a[axis] == b[axis]) continue;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // the other two, in axis order below
    const int first = std::min(u, v), second = std::max(u, v);
    return axis * 4 + lo[first] + 2 * lo[second];
  }
  throw std::logic_error("marching cubes: corners are not adjacent");
}

std::array<int8_t, 256 * kStride> build() {
  // Faces with corners counter-clockwise seen from outside the cube.
  std::vector<std::array<int, 4>> faces;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u × e_v = e_axis
    for (int side = 0; side < 2; ++side) {
      std::array<int, 4> f{};
      const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector3i p = Eigen::Vector3i::Zero();
        p[axis] = side;
        p[u] = uv[k][0];
        p[v] = uv[k][1];
        f[size_t(k)] = p.x() + 2 * p.y() + 4 * p.z();
      }
      if (side == 0) std::swap(f[1], f[3]);  // outward normal is −e_axis: reverse the order
      faces.push_back(f);
    }
  }
  std::array<int8_t, 256 * kStride> table;
  table.fill(-1);
  for (int m = 0; m < 256; ++m) {
    const auto inside = [&](int c) { return (m >> c) & 1; };
    int next[12];
    for (int& n : next) n = -1;
    for (const auto& f : faces) {
      for (int k = 0; k < 4; ++k) {
        const int a = f[size_t(k)], b = f[size_t((k + 1) % 4)];
        if (inside(a) || !inside(b)) continue;  // not an entry (outside -> inside)
        for (int j = 1; j < 4; ++j) {           // the first exit after it, counter-clockwise
          const int c = f[size_t((k + j) % 4)], d = f[size_t((k + j + 1) % 4)];
          if (inside(c) && !inside(d)) {
            next[edge_between(a, b)] = edge_between(c, d);
            break;
          }
        }
      }
    }
    int out = 0;
    bool used[12] = {};
    for (int start = 0; start < 12; ++start) {
      if (next[start] < 0 || used[start]) continue;
      std::vector<int> loop;
      for (int e = start; !used[e]; e = next[e]) {
        used[e] = true;
        loop.push_back(e);
        if (next[e] < 0) throw std::logic_error("marching cubes: open polygon");
      }
      for (size_t i = 1; i + 1 < loop.size(); ++i) {
        if (out + 3 >= kStride) throw std::logic_error("marching cubes: case table overflow");
        table[size_t(m * kStride + out++)] = int8_t(loop[0]);
        table[size_t(m * kStride + out++)] = int8_t(loop[i]);
        table[size_t(m * kStride + out++)] = int8_t(loop[i + 1]);
      }
    }
  }
  return table;
}

}  // namespace

const std::array<int8_t, 256 * kStride>& triangle_table() {
  static const std::array<int8_t, 256 * kStride> table = build();
  return table;
}

}  // namespace rrg::mc
