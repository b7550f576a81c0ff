#include "core/eval/association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace rrg::eval {

std::vector<PoseMatch> associate_by_time(const io::Trajectory& est, const io::Trajectory& ref,
                                         double max_dt) {
  if (!std::isfinite(max_dt) || max_dt < 0.0)
    throw std::invalid_argument("associate_by_time: max time difference must be finite and >= 0");

  // Reference indices sorted by time, so each estimated pose finds its window by binary search.
  std::vector<size_t> ref_order(ref.size());
  std::iota(ref_order.begin(), ref_order.end(), size_t{0});
  std::stable_sort(ref_order.begin(), ref_order.end(),
                   [&](size_t a, size_t b) { return ref[a].timestamp < ref[b].timestamp; });
  std::vector<double> ref_times(ref.size());
  for (size_t k = 0; k < ref_order.size(); ++k) ref_times[k] = ref[ref_order[k]].timestamp;

  struct Candidate {
    double dt;
    size_t est, ref;
  };
  std::vector<Candidate> candidates;
  for (size_t i = 0; i < est.size(); ++i) {
    const double t = est[i].timestamp;
    auto it = std::lower_bound(ref_times.begin(), ref_times.end(), t - max_dt);
    for (; it != ref_times.end() && *it <= t + max_dt; ++it) {
      const size_t k = size_t(it - ref_times.begin());
      candidates.push_back({std::abs(t - *it), i, ref_order[k]});
    }
  }
  // Smallest difference first; ties broken by index so the result never depends on sort order.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.dt, a.est, a.ref) < std::tie(b.dt, b.est, b.ref);
  });

  std::vector<bool> est_used(est.size(), false), ref_used(ref.size(), false);
  std::vector<PoseMatch> matches;
  for (const Candidate& c : candidates) {
    if (est_used[c.est] || ref_used[c.ref]) continue;
    est_used[c.est] = ref_used[c.ref] = true;
    matches.push_back({c.est, c.ref});
  }
  std::sort(matches.begin(), matches.end(), [&](const PoseMatch& a, const PoseMatch& b) {
    return std::tie(est[a.est].timestamp, a.est) < std::tie(est[b.est].timestamp, b.est);
  });
  return matches;
}

}  // namespace rrg::eval
