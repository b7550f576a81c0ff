// Known answers for the global-id stability score of `rrg planes eval` (core/planes/plane_metrics.h).
#include "core/planes/plane_metrics.h"

#include <gtest/gtest.h>

namespace rrg {
namespace {

// A 10x10 frame: GT plane 1 on the left half, GT plane 2 on the right half; the global map gives
// each half one id.
void add_frame(IdentificationScorer& s, int left_id, int right_id) {
  LabelImage gt(10, 10, 0);
  Image<int32_t> global(10, 10, 0);
  for (int v = 0; v < 10; ++v)
    for (int u = 0; u < 10; ++u) {
      gt(u, v) = u < 5 ? 1 : 2;
      global(u, v) = u < 5 ? left_id : right_id;
    }
  s.add(gt, global);
}

TEST(IdStability, CountsPlanesKeepingOneIdAndListsTheOthers) {
  IdentificationScorer s;
  // GT 1 keeps id 3 in all 20 frames. GT 2 has id 4 in 18 frames and id 3 in 2 (90 % < 95 %).
  for (int f = 0; f < 20; ++f) add_frame(s, 3, f < 18 ? 4 : 3);
  const IdStability st = s.id_stability({});
  EXPECT_EQ(st.planes, 2);
  EXPECT_EQ(st.stable, 1);
  EXPECT_EQ(st.frames, 40);
  EXPECT_EQ(st.consistent, 38);
  ASSERT_EQ(st.unstable.size(), 1u);
  ASSERT_TRUE(st.unstable.count(2));
  EXPECT_EQ(st.unstable.at(2).at(4), 18);
  EXPECT_EQ(st.unstable.at(2).at(3), 2);
  // Where the unstable plane's ids come from: id 4 is GT 2's, id 3 holds GT 1's pixels mostly.
  EXPECT_EQ(st.majority_gt.at(4), 2);
  EXPECT_EQ(st.majority_gt.at(3), 1);
}

TEST(IdStability, AMergeInTheRemapTableMakesTwoIdsOne) {
  IdentificationScorer s;
  for (int f = 0; f < 20; ++f) add_frame(s, 3, f < 10 ? 4 : 5);  // GT 2 split into 4 and 5
  EXPECT_EQ(s.id_stability({}).stable, 1);
  const std::vector<int32_t> remap = {0, 1, 2, 3, 4, 4};  // 5 was absorbed by 4
  const IdStability st = s.id_stability(remap);
  EXPECT_EQ(st.stable, 2);
  EXPECT_TRUE(st.unstable.empty());
  EXPECT_EQ(st.fraction(), 1.0);
}

}  // namespace
}  // namespace rrg
