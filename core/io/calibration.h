#pragma once
// Internal to core/io: camera calibrations of the supported datasets, as named constants and as
// the files those datasets ship. Every reader throws std::runtime_error naming the file.
#include "core/common/camera.h"

#include <filesystem>
#include <optional>
#include <string>

namespace rrg::io {

// A calibration file's intrinsics plus the depth scale when the file states one.
struct Calibration {
  Intrinsics intrinsics;
  std::optional<float> depth_scale;
};

// Named calibrations: freiburg1|2|3 (also fr1|2|3; TUM, 640x480), 7scenes (640x480), replica
// (1200x680). Case-insensitive; nullopt for an unknown name.
std::optional<Intrinsics> named_intrinsics(const std::string& name);

// Our camera.json: {"width","height","fx","fy","cx","cy"[,"depth_scale"]} (synth and TUM folders).
Calibration read_camera_json(const std::filesystem::path& path);
// Replica / NICE-SLAM cam_params.json: {"camera":{"w","h","fx","fy","cx","cy"[,"scale"]}}.
Calibration read_cam_params_json(const std::filesystem::path& path);
// 7-Scenes / 3DMatch camera-intrinsics.txt: a 3x3 K matrix, whitespace separated (no size).
Intrinsics read_k_matrix_txt(const std::filesystem::path& path);

// Width and height of an image file (decodes it; used once per dataset for the first frame).
Eigen::Vector2i image_size(const std::filesystem::path& path);

}  // namespace rrg::io
