#include "core/synth/presets.h"

#include <stdexcept>

namespace rrg::synth {

const std::vector<PresetInfo>& preset_list() {
  static const std::vector<PresetInfo> kPresets = {
      {"living_room", "glossy tiled floor, glossy TV screen and coffee table, sofa, shelves, lamp, posters"},
      {"mirror_room", "large wall mirror (F0 0.9) and a glossy wooden floor reflecting armchair, shelf, lamp"},
      {"office", "matte control scene (F0 = 0 everywhere): desks, chairs, shelves, whiteboards, carpet"},
      {"open_plan", "12 x 9 m open-plan flat (108 m²): polished concrete floor, lounge with glossy TV and table, "
                    "kitchen with a glossy island, dining table, study alcove, hall"},
  };
  return kPresets;
}

std::string preset_names() {
  std::string out;
  for (const PresetInfo& p : preset_list()) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

SceneSpec make_preset(const std::string& name, uint32_t seed) {
  if (name == "living_room") return make_living_room(seed);
  if (name == "mirror_room") return make_mirror_room(seed);
  if (name == "office") return make_office(seed);
  if (name == "open_plan") return make_open_plan(seed);
  throw std::invalid_argument("unknown preset '" + name + "' (valid presets: " + preset_names() + ")");
}

}  // namespace rrg::synth
