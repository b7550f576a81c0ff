// The semantic cues: none (every plane a candidate), labels (category table lookup), remote
// (without gRPC in the build: a clear error), and the prompt helpers.
#include "core/planes/remote_segmenter.h"
#include "core/planes/semantic_cue.h"
#include "core/planes/semantic_labels.h"

#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <fstream>

namespace rrg {
namespace {

TEST(SemanticCue, PaperPromptsAndParsing) {
  EXPECT_EQ(paper_prompts(), (std::vector<std::string>{"floor", "table", "vending machine", "closet", "wall art", "tv",
                                                       "whiteboard"}));
  EXPECT_EQ(parse_prompt_list(" Floor, wall art ,,tv"), (std::vector<std::string>{"floor", "wall art", "tv"}));
  EXPECT_TRUE(label_in("TV ", paper_prompts()));
  EXPECT_TRUE(label_in("wall art", paper_prompts()));
  EXPECT_FALSE(label_in("wall", paper_prompts()));
}

TEST(SemanticCue, NoneMakesEveryPlaneACandidate) {
  auto cue = make_no_semantics();
  EXPECT_EQ(cue->name(), "none");
  EXPECT_TRUE(cue->every_plane_is_candidate());
  const ColorImage c(4, 4);
  EXPECT_TRUE(cue->segment({&c, nullptr, 0}).empty());
}

TEST(SemanticCue, LabelsLookUpTheCategoryTable) {
  test::TempDir dir("planes_cue");
  {
    std::ofstream f(dir / "categories.json");
    f << R"({"categories": [{"id": 1, "name": "floor", "reflective": false},
                            {"id": 2, "name": "wall", "reflective": true},
                            {"id": 5, "name": "tv"}]})";
  }
  const CategoryTable table = read_category_table(dir / "categories.json");
  EXPECT_EQ(table.name(1), "floor");
  EXPECT_EQ(table.name(9), "category_9");
  auto cue = make_label_semantics(table, paper_prompts());
  EXPECT_EQ(cue->name(), "labels");
  EXPECT_FALSE(cue->every_plane_is_candidate());
  // 3x2 labels: floor floor wall / tv none 9
  LabelImage labels(3, 2, 0);
  labels(0, 0) = 1, labels(1, 0) = 1, labels(2, 0) = 2, labels(0, 1) = 5, labels(2, 1) = 9;
  const ColorImage color(3, 2);
  const auto masks = cue->segment({&color, &labels, 7});
  ASSERT_EQ(masks.size(), 4u);  // floor, wall, tv, category_9, in order of first appearance
  EXPECT_EQ(masks[0].label, "floor");
  EXPECT_TRUE(masks[0].reflective);   // the prompts decide, not the file's flag
  EXPECT_EQ(masks[1].label, "wall");
  EXPECT_FALSE(masks[1].reflective);
  EXPECT_EQ(masks[2].label, "tv");
  EXPECT_TRUE(masks[2].reflective);
  EXPECT_EQ(masks[3].label, "category_9");
  EXPECT_EQ(std::vector<uint8_t>(masks[0].mask.pixels().begin(), masks[0].mask.pixels().end()),
            (std::vector<uint8_t>{1, 1, 0, 0, 0, 0}));
  EXPECT_EQ(masks[2].mask(0, 1), 1);
  EXPECT_EQ(masks[2].mask(1, 1), 0);
}

TEST(SemanticCue, LabelsErrorsNameTheProblem) {
  test::TempDir dir("planes_cue_err");
  try {
    read_category_table(dir / "missing.json");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.json"), std::string::npos);
  }
  {
    std::ofstream f(dir / "bad.json");
    f << "{\"categories\": [{\"id\": 1}]}";
  }
  EXPECT_THROW(read_category_table(dir / "bad.json"), std::runtime_error);
  EXPECT_THROW(make_label_semantics({}, {}), std::invalid_argument);
  auto cue = make_label_semantics({}, paper_prompts());
  const ColorImage color(2, 2);
  try {
    cue->segment({&color, nullptr, 3});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("frame 3 has no label image"), std::string::npos);
  }
  const LabelImage small(1, 1, 1);
  EXPECT_THROW(cue->segment({&color, &small, 0}), std::runtime_error);
}

TEST(SemanticCue, RemoteNeedsAnAddressAndSaysWhenTheBuildHasNoGrpc) {
  RemoteSegmenterOptions o;
  EXPECT_THROW(make_remote_semantics(o), std::invalid_argument);
  o.address = "127.0.0.1:1";
  if (remote_segmenter_available()) {
    // With gRPC: a call to a port nobody listens on fails with the address in the message.
    o.timeout_s = 2.0;
    auto cue = make_remote_semantics(o);
    const ColorImage color(4, 4);
    try {
      cue->segment({&color, nullptr, 0});
      FAIL();
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("127.0.0.1:1"), std::string::npos) << e.what();
    }
  } else {
    try {
      make_remote_semantics(o);
      FAIL();
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("no gRPC"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace rrg
