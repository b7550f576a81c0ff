#pragma once
// The semantic cue of reflective plane identification (paper §4.1.3) behind one interface. A cue
// turns a frame into instance masks with a label and a score; masks whose label is one of the
// reflective categories (the text prompts) make the planes they overlap most reflective-plane
// candidates. Three implementations:
//   none    every plane is a candidate; the temporal variance check alone decides;
//   labels  per-frame label images supplied with the frame + a category table (id -> name), as AR
//           devices and our synthetic generator provide (semantic_labels.h);
//   remote  a segmenter in another process over gRPC, rrg.v1.Segmenter (remote_segmenter.h), so
//           Grounded SAM2 can run in its own process.
#include "core/common/image.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rrg {

// The paper's Grounded SAM2 prompts (supplement, "Grounded SAM2 Settings").
const std::vector<std::string>& paper_prompts();
// Our default: the paper's prompts plus "mirror" (the RIRD scenes have no mirrors; a mirror is the
// most reflective surface an indoor capture meets).
const std::vector<std::string>& default_prompts();

struct SemanticMask {
  MaskImage mask;            // 0 / 1, the frame's size
  std::string label;         // category or prompt that produced it
  float score = 1.0f;        // detector confidence in [0, 1]
  bool reflective = false;   // label is one of the reflective categories
};

// What a cue may look at: the colour image and, when the dataset supplies them, label images.
struct SemanticFrame {
  const ColorImage* color = nullptr;   // required
  const LabelImage* labels = nullptr;  // per-pixel category ids (0 = none), optional
  int64_t index = 0;                   // frame index
};

class SemanticCue {
 public:
  virtual ~SemanticCue() = default;
  virtual std::string name() const = 0;  // "none" | "labels" | "remote"
  // True when there are no semantics: every plane is a candidate.
  virtual bool every_plane_is_candidate() const { return false; }
  // True when masks come with every frame at no real cost (labels supplied with the frame), so a
  // caller may ask for them on frames that do not identify (the depth fill, reflective_fill.h).
  virtual bool masks_with_every_frame() const { return false; }
  // Instance masks of one frame (throws std::runtime_error naming the problem).
  virtual std::vector<SemanticMask> segment(const SemanticFrame& frame) = 0;
};

// Case-insensitive membership of a label in a prompt list (surrounding spaces ignored).
bool label_in(const std::string& label, const std::vector<std::string>& prompts);
// "floor, table" or "floor,table" -> {"floor", "table"}; empty items dropped.
std::vector<std::string> parse_prompt_list(const std::string& text);

// The `none` cue.
std::unique_ptr<SemanticCue> make_no_semantics();

}  // namespace rrg
