// 7-Scenes / 3DMatch sequence folders: frame-NNNNNN.color.{png,jpg}, frame-NNNNNN.depth.png
// (millimetres), frame-NNNNNN.pose.txt (4x4 camera-to-world), camera-intrinsics.txt (3x3 K).
#include "core/io/calibration.h"
#include "core/io/frame_list_dataset.h"
#include "core/io/text_parse.h"

#include <spdlog/spdlog.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

constexpr float kMillimetres = 1000.0f;
constexpr uint16_t kNoReading = 65535;  // the original 7-Scenes release marks missing depth so
constexpr double kFps = 30.0;

struct Files {
  fs::path color, depth, pose;
};

// "frame-000123.color.jpg" -> (123, "color.jpg"); nullopt for other names.
std::optional<std::pair<long, std::string>> split_name(const std::string& name) {
  if (!name.starts_with("frame-")) return std::nullopt;
  size_t i = 6;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  if (i == 6 || i >= name.size() || name[i] != '.') return std::nullopt;
  return std::make_pair(std::stol(name.substr(6, i - 6)), name.substr(i + 1));
}

std::optional<Eigen::Isometry3d> read_pose(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open pose file " + path.string());
  std::stringstream text;
  text << in.rdbuf();
  const std::string s = text.str();
  const auto fields = split_fields(s);
  if (fields.size() != 16)
    throw std::runtime_error("pose file " + path.string() + ": expected 16 numbers (4x4), got " +
                             std::to_string(fields.size()));
  double m[16];
  for (int k = 0; k < 16; ++k) {
    const auto v = parse_double(fields[k]);
    if (!v) throw std::runtime_error("pose file " + path.string() + ": '" + std::string(fields[k]) + "' is not a number");
    m[k] = *v;
  }
  return rigid_from_rows(m, "pose file " + path.string());
}

}  // namespace

std::unique_ptr<Dataset> open_seven_scenes(const fs::path& root, const DatasetOptions& options) {
  std::map<long, Files> by_number;
  for (const auto& entry : fs::directory_iterator(root)) {
    const auto parts = split_name(entry.path().filename().string());
    if (!parts) continue;
    Files& f = by_number[parts->first];
    const std::string& kind = parts->second;
    if (kind == "color.png" || kind == "color.jpg") f.color = entry.path();
    else if (kind == "depth.png") f.depth = entry.path();
    else if (kind == "pose.txt") f.pose = entry.path();
  }
  auto expected = [&](long n, const char* suffix) {
    char name[64];
    std::snprintf(name, sizeof(name), "frame-%06ld.%s", n, suffix);
    return root / name;
  };

  FrameList list;
  list.format = DatasetFormat::SevenScenes;
  list.root = root;
  list.invalid_depth = kNoReading;
  list.depth_scale = options.depth_scale.value_or(kMillimetres);
  const fs::path k_file = root / "camera-intrinsics.txt";
  if (fs::exists(k_file)) {
    list.intrinsics = read_k_matrix_txt(k_file);
    if (options.intrinsics) {
      spdlog::warn("{} overrides --intrinsics", k_file.string());
      if (options.intrinsics->width > 0) {  // a named calibration also gives the image size
        list.intrinsics.width = options.intrinsics->width;
        list.intrinsics.height = options.intrinsics->height;
      }
    }
  } else {
    list.intrinsics = options.intrinsics.value_or(*named_intrinsics("7scenes"));
  }
  size_t without_pose = 0;
  for (const auto& [n, f] : by_number) {
    if (f.color.empty() && f.depth.empty()) continue;  // a stray pose file: ignored
    if (f.color.empty())
      throw std::runtime_error("missing file " + expected(n, "color.png").string() + " (or .jpg) for " +
                               f.depth.string());
    if (f.depth.empty())
      throw std::runtime_error("missing file " + expected(n, "depth.png").string() + " for " + f.color.string());
    FrameEntry e;
    e.timestamp = double(n) / kFps;
    e.color = f.color;
    e.depth = f.depth;
    if (!f.pose.empty()) e.T_wc = read_pose(f.pose);
    if (!e.T_wc) ++without_pose;
    list.frames.push_back(std::move(e));
  }
  if (list.frames.empty()) throw std::runtime_error("7-Scenes folder " + root.string() + " has no frame-*.color.* files");
  if (without_pose > 0 && without_pose < list.frames.size())
    spdlog::warn("{}: {} of {} frames have no (valid) pose file", root.string(), without_pose, list.frames.size());
  return std::make_unique<FrameListDataset>(std::move(list));
}

}  // namespace rrg::io
