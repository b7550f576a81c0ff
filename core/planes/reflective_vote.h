#pragma once
// The temporal vote of reflective plane identification (paper §4.1.3): per global plane, the
// variance-check outcome of its most recent windows (identification steps in which it was seen);
// a plane enters the reflective plane lookup table L_ref when it was reflective in more than 3 of
// the last 5. Entries stay in L_ref. Merged planes pool their histories.
#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <utility>

namespace rrg {

struct PlaneStateIo;

struct ReflectiveVoteParams {
  int windows = 5;        // history length
  int min_reflective = 4; // "more than three"
  void validate() const;  // throws std::invalid_argument
};

class ReflectiveVote {
 public:
  explicit ReflectiveVote(const ReflectiveVoteParams& params = {});

  // Records plane `id`'s outcome in window `window` (an identification step index); a second
  // record of the same window ORs into the first. Returns true when the plane is in L_ref after it.
  bool record(int id, int64_t window, bool reflective);
  // Pools `absorbed`'s history into `kept` (union-find merge of the plane table).
  void merge(int kept, int absorbed);

  bool accepted(int id) const { return lookup_.count(id) > 0; }
  int reflective_count(int id) const;     // reflective outcomes among the kept history
  int history_size(int id) const;
  const std::set<int>& lookup_table() const { return lookup_; }  // L_ref
  const ReflectiveVoteParams& params() const { return params_; }

 private:
  friend struct PlaneStateIo;  // snapshots (plane_state_io.h)
  ReflectiveVoteParams params_;
  std::map<int, std::deque<std::pair<int64_t, bool>>> history_;  // id -> (window, outcome), oldest first
  std::set<int> lookup_;
};

}  // namespace rrg
