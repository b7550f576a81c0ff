#pragma once
// Timestamp association as the TUM RGB-D benchmark's associate.py: all pairs with |a - b| <
// max_difference, taken greedily by smallest |a - b| (ties by a, then b), each stamp used once,
// the result sorted by a. Also the nearest-stamp lookup used for ground-truth poses.
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace rrg::io {

// Index pairs (i into a, j into b), sorted by a[i].
std::vector<std::pair<size_t, size_t>> associate_stamps(std::span<const double> a, std::span<const double> b,
                                                        double max_difference);

// Index of the stamp in `sorted` (ascending) nearest to t, if |t - stamp| < max_difference.
std::optional<size_t> nearest_stamp(std::span<const double> sorted, double t, double max_difference);

}  // namespace rrg::io
