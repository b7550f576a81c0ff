#include "core/synth/categories.h"

#include <array>

namespace rrg::synth {

std::string_view category_name(Category category) {
  static constexpr std::array<std::string_view, size_t(Category::Count)> kNames = {
      "none",   "floor", "wall",  "ceiling",    "table", "tv",      "mirror",
      "sofa",   "shelf", "lamp",  "poster",     "rug",   "desk",    "whiteboard",
      "chair",  "cabinet", "plant", "books",    "door",  "sculpture", "monitor"};
  const auto i = size_t(category);
  return i < kNames.size() ? kNames[i] : std::string_view("unknown");
}

}  // namespace rrg::synth
