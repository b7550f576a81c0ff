// The 5-window vote: accepted into L_ref when reflective in more than 3 of the last 5 windows.
#include "core/planes/reflective_vote.h"

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

}  // namespace
}  // namespace rrg
