#pragma once
// The scene presets of `rrg synth`: rooms about 5 x 4 x 2.7 m and a 12 x 9 x 2.8 m flat (world z up,
// floor at z = 0) with planar reflective surfaces, each with a hand-placed closed camera loop.
#include "core/synth/camera_path.h"
#include "core/synth/scene.h"

#include <string>
#include <vector>

namespace rrg::synth {

struct PresetInfo {
  std::string name;
  std::string description;  // one line
};

struct SceneSpec {
  Scene scene;                       // finalized
  std::vector<Waypoint> waypoints;   // camera loop (eye, look-at target)
};

// All presets, in a fixed order.
const std::vector<PresetInfo>& preset_list();
// "living_room, mirror_room, office, open_plan" (for error messages and help).
std::string preset_names();
// Builds a preset; seed varies textures only. Throws std::invalid_argument naming the valid
// presets for an unknown name.
SceneSpec make_preset(const std::string& name, uint32_t seed);

// The individual presets (preset_<name>.cpp).
SceneSpec make_living_room(uint32_t seed);
SceneSpec make_mirror_room(uint32_t seed);
SceneSpec make_office(uint32_t seed);
SceneSpec make_open_plan(uint32_t seed);

}  // namespace rrg::synth
