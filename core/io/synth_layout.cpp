#include "core/io/synth_layout.h"

#include "core/io/image_io.h"

#include <cstdio>
#include <stdexcept>
#include <string>

namespace rrg::io {

namespace fs = std::filesystem;

fs::path synth_extra_path(const fs::path& root, std::string_view kind, size_t frame_index) {
  if (kind != "rgb" && kind != "depth" && kind != "labels" && kind != "reflection" && kind != "planes")
    throw std::invalid_argument("unknown synth per-frame folder '" + std::string(kind) +
                                "' (expected rgb|depth|labels|reflection|planes)");
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", frame_index);
  return root / std::string(kind) / name;
}

LabelImage read_synth_labels(const fs::path& root, size_t frame_index) {
  return read_labels(synth_extra_path(root, "labels", frame_index));
}

MaskImage read_synth_reflection(const fs::path& root, size_t frame_index) {
  return read_mask(synth_extra_path(root, "reflection", frame_index));
}

LabelImage read_synth_planes(const fs::path& root, size_t frame_index) {
  return read_labels(synth_extra_path(root, "planes", frame_index));
}

fs::path synth_scene_file(const fs::path& root, std::string_view name) {
  if (name != "categories.json" && name != "planes.json" && name != "mesh_gt.ply" && name != "scene.json" &&
      name != "novel")
    throw std::invalid_argument("unknown synth scene file '" + std::string(name) +
                                "' (expected categories.json|planes.json|mesh_gt.ply|scene.json|novel)");
  return root / std::string(name);
}

}  // namespace rrg::io
