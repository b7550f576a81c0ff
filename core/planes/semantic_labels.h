#pragma once
// The `labels` semantic cue: per-frame label images (category id per pixel) supplied with the
// frame, and a category table id -> name. One mask per category present in the frame; a mask is
// reflective when its category name is one of the prompts. categories.json of the synthetic
// layout gives the table; its "reflective" flags come from the ground-truth materials and are
// deliberately ignored (the prompts decide, as with Grounded SAM2).
#include "core/planes/semantic_cue.h"

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace rrg {

struct CategoryTable {
  std::map<uint16_t, std::string> names;  // id -> name; 0 is "none"
  std::string name(uint16_t id) const;    // "category_<id>" for unknown ids
};

// Reads {"categories": [{"id": 1, "name": "floor", ...}, ...]}; throws std::runtime_error naming
// the file for a missing file or bad JSON.
CategoryTable read_category_table(const std::filesystem::path& file);

// Throws std::invalid_argument for an empty prompt list. segment() throws when the frame has no
// label image or its size differs from the colour image.
std::unique_ptr<SemanticCue> make_label_semantics(CategoryTable table, std::vector<std::string> prompts);

}  // namespace rrg
