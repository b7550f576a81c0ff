#include "core/io/tum_association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace rrg::io {

std::vector<std::pair<size_t, size_t>> associate_stamps(std::span<const double> a, std::span<const double> b,
                                                        double max_difference) {
  // b sorted by time, so each a only looks at the b's inside its window.
  std::vector<size_t> b_order(b.size());
  std::iota(b_order.begin(), b_order.end(), size_t{0});
  std::stable_sort(b_order.begin(), b_order.end(), [&](size_t x, size_t y) { return b[x] < b[y]; });
  std::vector<double> b_sorted(b.size());
  for (size_t k = 0; k < b.size(); ++k) b_sorted[k] = b[b_order[k]];

  std::vector<std::tuple<double, double, double, size_t, size_t>> candidates;  // |dt|, a, b, i, j
  for (size_t i = 0; i < a.size(); ++i) {
    auto it = std::lower_bound(b_sorted.begin(), b_sorted.end(), a[i] - max_difference);
    for (; it != b_sorted.end() && *it < a[i] + max_difference; ++it) {
      const double dt = std::abs(a[i] - *it);
      if (dt < max_difference) {
        const size_t j = b_order[size_t(it - b_sorted.begin())];
        candidates.emplace_back(dt, a[i], b[j], i, j);
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<bool> a_used(a.size(), false), b_used(b.size(), false);
  std::vector<std::pair<size_t, size_t>> matches;
  for (const auto& [dt, ta, tb, i, j] : candidates) {
    if (a_used[i] || b_used[j]) continue;
    a_used[i] = b_used[j] = true;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end(), [&](const auto& x, const auto& y) {
    return a[x.first] != a[y.first] ? a[x.first] < a[y.first] : b[x.second] < b[y.second];
  });
  return matches;
}

std::optional<size_t> nearest_stamp(std::span<const double> sorted, double t, double max_difference) {
  const auto it = std::lower_bound(sorted.begin(), sorted.end(), t);
  std::optional<size_t> best;
  double best_dt = max_difference;
  auto consider = [&](size_t k) {
    const double dt = std::abs(sorted[k] - t);
    if (dt < best_dt) best_dt = dt, best = k;
  };
  const size_t k = size_t(it - sorted.begin());
  if (k < sorted.size()) consider(k);
  if (k > 0) consider(k - 1);
  return best;
}

}  // namespace rrg::io
