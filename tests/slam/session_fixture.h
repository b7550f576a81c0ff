#pragma once
// Shared fixture of the session tests (session_test.cpp, snapshot_test.cpp): a small synthetic
// mirror_room sequence with depth noise, synthesised once per test suite into a temporary folder
// by the real `rrg synth`, and the config and frame builders both suites start from.
#include "core/io/dataset.h"
#include "core/io/synth_layout.h"
#include "core/planes/semantic_labels.h"
#include "core/slam/session.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

namespace rrg::test {

// The labels cue as a `remote` one behaves: masks on identification frames only (every N_p = 10).
class IdentificationFrameLabels final : public SemanticCue {
 public:
  explicit IdentificationFrameLabels(std::unique_ptr<SemanticCue> labels) : labels_(std::move(labels)) {}
  std::string name() const override { return "remote"; }
  std::vector<SemanticMask> segment(const SemanticFrame& f) override {
    ++calls;
    return labels_->segment(f);
  }
  int calls = 0;

 private:
  std::unique_ptr<SemanticCue> labels_;
};

// Suite is the derived fixture (CRTP), so each suite owns its folder. Frames is the sequence length.
template <class Suite, size_t Frames>
class SynthSessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("session");
    const auto r = run_rrg("synth --preset mirror_room --frames " + std::to_string(Frames) +
                           " --width 160 --height 120 --novel 2 --noise --out " + root().string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::filesystem::path root() { return dir_->path() / "seq"; }

  // CPU, 2 cm voxels (a coarse map keeps the tests fast), ICP, the `labels` cue with the scene's
  // categories, deterministic sync mode, 5 mapping iterations.
  static SessionConfig base_config(const io::Dataset& d) {
    SessionConfig c;
    c.K = d.intrinsics();
    c.tsdf.voxel_size = 0.02f;
    c.tsdf.truncation = 0.08f;
    c.tracking.mode = TrackingMode::Icp;
    c.semantics = "labels";
    for (const auto& [id, name] : read_category_table(io::synth_scene_file(root(), "categories.json")).names)
      c.categories[id] = name;
    c.sync = true;
    c.mapping.iterations = 5;
    return c;
  }
  static CategoryTable categories() { return read_category_table(io::synth_scene_file(root(), "categories.json")); }
  static uint16_t category_id(const std::string& name) {  // 0 when the scene has no such category
    for (const auto& [id, n] : categories().names)
      if (n == name) return id;
    return 0;
  }
  // Frame i with its labels; with its ground-truth pose when with_pose.
  static SessionFrame frame(const io::Dataset& d, size_t i, bool with_pose) {
    io::Frame f = d.load(i);
    SessionFrame s;
    s.index = int64_t(i);
    s.timestamp = f.timestamp;
    s.color = std::move(f.color);
    s.depth = std::move(f.depth);
    s.labels = io::read_synth_labels(root(), i);
    if (with_pose) s.pose = f.T_wc_gt->cast<float>();
    return s;
  }

 private:
  static inline std::unique_ptr<TempDir> dir_;
};

}  // namespace rrg::test
