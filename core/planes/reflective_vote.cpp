#include "core/planes/reflective_vote.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rrg {

void ReflectiveVoteParams::validate() const {
  if (windows < 1) throw std::invalid_argument("ReflectiveVoteParams: windows must be >= 1");
  if (min_reflective < 1 || min_reflective > windows)
    throw std::invalid_argument("ReflectiveVoteParams: min_reflective must be in [1, windows]");
}

ReflectiveVote::ReflectiveVote(const ReflectiveVoteParams& params) : params_(params) { params_.validate(); }

bool ReflectiveVote::record(int id, int64_t window, bool reflective) {
  auto& h = history_[id];
  auto it = std::find_if(h.begin(), h.end(), [&](const auto& e) { return e.first == window; });
  if (it != h.end()) {
    it->second = it->second || reflective;
  } else {
    h.emplace_back(window, reflective);
    std::sort(h.begin(), h.end());
    while (int(h.size()) > params_.windows) h.pop_front();
  }
  if (reflective_count(id) >= params_.min_reflective) lookup_.insert(id);
  return accepted(id);
}

void ReflectiveVote::merge(int kept, int absorbed) {
  if (kept == absorbed) return;
  const auto it = history_.find(absorbed);
  if (it != history_.end()) {
    const auto entries = it->second;
    history_.erase(it);
    for (const auto& [window, outcome] : entries) record(kept, window, outcome);
  }
  if (lookup_.erase(absorbed) > 0) lookup_.insert(kept);
}

int ReflectiveVote::reflective_count(int id) const {
  const auto it = history_.find(id);
  if (it == history_.end()) return 0;
  return int(std::count_if(it->second.begin(), it->second.end(), [](const auto& e) { return e.second; }));
}

int ReflectiveVote::history_size(int id) const {
  const auto it = history_.find(id);
  return it == history_.end() ? 0 : int(it->second.size());
}

}  // namespace rrg
