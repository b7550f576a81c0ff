// The 5-window vote: accepted into L_ref when reflective in more than 3 of the last 5 windows.
#include "core/planes/reflective_vote.h"

#include "core/planes/plane_identification.h"

#include <gtest/gtest.h>

namespace rrg {
namespace {

TEST(ReflectiveVote, FourOfFiveAccepts) {
  ReflectiveVote v;
  EXPECT_FALSE(v.record(7, 0, true));
  EXPECT_FALSE(v.record(7, 1, true));
  EXPECT_FALSE(v.record(7, 2, false));
  EXPECT_FALSE(v.record(7, 3, true));  // 3 of 4: not more than three
  EXPECT_TRUE(v.record(7, 4, true));   // 4 of 5
  EXPECT_TRUE(v.accepted(7));
  EXPECT_EQ(v.lookup_table(), (std::set<int>{7}));
  EXPECT_TRUE(v.record(7, 5, false));  // stays in L_ref
}

TEST(ReflectiveVote, OnlyTheLastFiveWindowsCount) {
  ReflectiveVote v;
  // T T T F F F T T: never 4 of the last 5.
  const bool seq[] = {true, true, true, false, false, false, true, true};
  for (int w = 0; w < 8; ++w) EXPECT_FALSE(v.record(1, w, seq[w])) << "window " << w;
  EXPECT_EQ(v.history_size(1), 5);
  EXPECT_EQ(v.reflective_count(1), 2);
  EXPECT_FALSE(v.record(1, 8, true));  // F F T T T: 3
  EXPECT_TRUE(v.record(1, 9, true));   // F T T T T: 4
}

TEST(ReflectiveVote, SameWindowOrsAndMergePoolsHistories) {
  ReflectiveVote v;
  v.record(2, 0, false);
  v.record(2, 0, true);  // a second local piece of plane 2 in the same window
  EXPECT_EQ(v.history_size(2), 1);
  EXPECT_EQ(v.reflective_count(2), 1);
  v.record(3, 1, true);
  v.record(3, 2, true);
  v.record(2, 3, true);
  EXPECT_FALSE(v.accepted(2));
  v.merge(2, 3);  // plane 3 absorbed into 2: windows 0..3 all reflective
  EXPECT_EQ(v.reflective_count(2), 4);
  EXPECT_TRUE(v.accepted(2));
  EXPECT_EQ(v.history_size(3), 0);
  EXPECT_FALSE(v.accepted(3));
}

TEST(ReflectiveVote, BadParamsThrow) {
  EXPECT_THROW(ReflectiveVote(ReflectiveVoteParams{5, 6}), std::invalid_argument);
  EXPECT_THROW(ReflectiveVote(ReflectiveVoteParams{0, 1}), std::invalid_argument);
}

// The planes whose reflection stays open for the tracking mask: semantic candidates without a
// decision, carried across windows that do not see them until their history is full.
TEST(ReflectiveVote, UndecidedCandidatesAreTheSemanticCandidatesWithAnOpenVote) {
  ReflectiveVote vote;
  const GlobalPlaneTable table;  // no merges: every id is its own canonical id
  IdentificationResult w;
  const auto verdict = [](int id, bool candidate) {
    PlaneVerdict v;
    v.global_id = id;
    v.candidate = candidate;
    return v;
  };
  // Window 0 sees a mirror (candidate) and a wall (no reflective mask); neither is reflective yet.
  w.planes = {verdict(1, true), verdict(2, false)};
  vote.record(1, 0, false);
  vote.record(2, 0, false);
  std::set<int> open = undecided_candidates({}, w, vote, table, false);
  EXPECT_EQ(open, std::set<int>({1}));
  EXPECT_TRUE(undecided_candidates({}, w, vote, table, true).empty()) << "`none`: candidacy says nothing";

  // Windows 1-3 do not see plane 1: it stays open while its history is short.
  for (int64_t k = 1; k <= 3; ++k) {
    w.planes = {verdict(2, false)};
    vote.record(2, k, false);
    open = undecided_candidates(open, w, vote, table, false);
  }
  EXPECT_EQ(open, std::set<int>({1}));

  // Reflective in windows 4-7: accepted after four of five, which closes it.
  for (int64_t k = 4; k <= 7; ++k) {
    w.planes = {verdict(1, true)};
    const bool accepted = vote.record(1, k, true);
    open = undecided_candidates(open, w, vote, table, false);
    EXPECT_EQ(open.count(1), accepted ? 0u : 1u) << "window " << k;
  }
  EXPECT_TRUE(vote.accepted(1));

  // A candidate that is never reflective closes as soon as four of its first five windows can no
  // longer be reflective: after two.
  for (int64_t k = 8; k <= 12; ++k) {
    w.planes = {verdict(3, true)};
    vote.record(3, k, false);
    open = undecided_candidates(open, w, vote, table, false);
    EXPECT_EQ(open.count(3), k < 9 ? 1u : 0u) << "window " << k;
  }
  // Reflective, then not, then not: 1 + 3 windows to come can still make four, 1 + 2 cannot.
  const bool outcomes[] = {true, false, false};
  for (int64_t k = 20; k < 23; ++k) {
    w.planes = {verdict(5, true)};
    vote.record(5, k, outcomes[k - 20]);
    open = undecided_candidates(open, w, vote, table, false);
    EXPECT_EQ(open.count(5), k < 22 ? 1u : 0u) << "window " << k;
  }
  // A plane seen as no candidate in a window is decided by that window.
  w.planes = {verdict(4, true)};
  vote.record(4, 13, false);
  open = undecided_candidates(open, w, vote, table, false);
  ASSERT_EQ(open.count(4), 1u);
  w.planes = {verdict(4, false)};
  vote.record(4, 14, false);
  EXPECT_EQ(undecided_candidates(open, w, vote, table, false).count(4), 0u);
}

}  // namespace
}  // namespace rrg
