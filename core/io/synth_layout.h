#pragma once
// The extras of our synthetic layout (written by core/synth, read by the evaluation tools). The
// frames themselves are read with open_dataset like any TUM folder; frame i's files are numbered i
// (rgb/NNNNNN.png, labels/NNNNNN.png, ...). novel/ is itself a synth-style TUM folder (no
// scene.json), so these helpers take it as a root too. Layout: docs/datasets.md.
#include "core/common/image.h"

#include <filesystem>
#include <string_view>

namespace rrg::io {

// root/<kind>/NNNNNN.png for kind = rgb | depth | labels | reflection | planes.
std::filesystem::path synth_extra_path(const std::filesystem::path& root, std::string_view kind, size_t frame_index);

// labels/NNNNNN.png: 16-bit semantic category id (categories.json), 0 = none.
LabelImage read_synth_labels(const std::filesystem::path& root, size_t frame_index);
// reflection/NNNNNN.png: ground-truth reflection mask R, stored 0 / 255, read as 0 / 1.
MaskImage read_synth_reflection(const std::filesystem::path& root, size_t frame_index);
// planes/NNNNNN.png: 16-bit plane id (planes.json), 0 = none.
LabelImage read_synth_planes(const std::filesystem::path& root, size_t frame_index);

// Whole-scene files: categories.json, planes.json, mesh_gt.ply, scene.json; novel/ (held-out views).
std::filesystem::path synth_scene_file(const std::filesystem::path& root, std::string_view name);

}  // namespace rrg::io
