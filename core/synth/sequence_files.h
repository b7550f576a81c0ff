#pragma once
// The metadata files of a synthetic sequence: TUM frame lists, camera.json, categories.json,
// planes.json and scene.json. All written atomically.
#include "core/common/camera.h"
#include "core/io/trajectory.h"
#include "core/synth/presets.h"
#include "core/synth/sequence.h"

#include <filesystem>
#include <string>

namespace rrg::synth {

// Writes text to path atomically; throws std::runtime_error naming the file.
void write_text_file(const std::filesystem::path& path, const std::string& text);
// Frame file name for index i: "000042.png".
std::string frame_file_name(size_t i);
// TUM list ("# ..." x3, then "timestamp folder/NNNNNN.png" per pose) for folder "rgb" or "depth".
void write_frame_list(const std::filesystem::path& path, const io::Trajectory& poses, const std::string& folder,
                      const std::string& title);
void write_camera_json(const std::filesystem::path& path, const Intrinsics& K);
void write_categories_json(const std::filesystem::path& path, const Scene& scene);
void write_planes_json(const std::filesystem::path& path, const Scene& scene);
void write_scene_json(const std::filesystem::path& path, const SceneSpec& spec, const CameraPath& path_loop,
                      const SynthParams& params, const SequencePlan& plan);

}  // namespace rrg::synth
