#pragma once
// Timestamp association of two pose streams, as TUM RGB-D's associate.py: every pair with
// |t_est − t_ref| ≤ max_dt is a candidate; candidates are taken greedily by increasing time
// difference, each estimated and each reference pose used at most once.
#include "core/io/trajectory.h"

#include <vector>

namespace rrg::eval {

struct PoseMatch {
  size_t est = 0;  // index into the estimated trajectory
  size_t ref = 0;  // index into the reference trajectory
};

// Matches sorted by estimated timestamp. Inputs need not be sorted. Throws std::invalid_argument
// when max_dt is negative or not finite.
std::vector<PoseMatch> associate_by_time(const io::Trajectory& est, const io::Trajectory& ref,
                                         double max_dt = 0.02);

}  // namespace rrg::eval
