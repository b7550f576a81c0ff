#pragma once
// Semantic categories of the synthetic scenes (labels/NNNNNN.png stores the id; 0 = none). Names
// follow the paper's semantic prompts where they overlap (floor, table, tv, whiteboard, ...).
#include <cstdint>
#include <string_view>

namespace rrg::synth {

enum class Category : uint16_t {
  None = 0,
  Floor,
  Wall,
  Ceiling,
  Table,
  Tv,
  Mirror,
  Sofa,
  Shelf,
  Lamp,
  Poster,
  Rug,
  Desk,
  Whiteboard,
  Chair,
  Cabinet,
  Plant,
  Books,
  Door,
  Sculpture,
  Monitor,
  Count
};

// Lower-case name of a category ("floor", "tv", ...); "none" for 0.
std::string_view category_name(Category category);

}  // namespace rrg::synth
