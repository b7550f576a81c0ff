// Format detection and the open_dataset entry point.
#include "core/io/dataset.h"
#include "core/io/frame_list_dataset.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

namespace rrg::io {

namespace fs = std::filesystem;

namespace {

bool has_frame_files(const fs::path& root) {
  for (const auto& entry : fs::directory_iterator(root)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("frame-") && (name.ends_with(".pose.txt") || name.find(".color.") != std::string::npos))
      return true;
  }
  return false;
}

// "data/seq/" -> "data/seq", so parent/own-name lookups work.
fs::path normalised(const fs::path& root) {
  fs::path p = root.lexically_normal();
  if (p.filename().empty() && p.has_parent_path()) p = p.parent_path();
  return p;
}

}  // namespace

DatasetFormat detect_dataset_format(const fs::path& root) {
  std::error_code ec;
  if (!fs::exists(root, ec)) throw std::runtime_error("dataset folder not found: " + root.string());
  if (!fs::is_directory(root, ec)) throw std::runtime_error("dataset path is not a folder: " + root.string());
  auto has = [&](const char* name) { return fs::exists(root / name, ec); };
  if (has("scene.json") && has("rgb.txt")) return DatasetFormat::Synth;
  if (has("rgb.txt") && has("depth.txt")) return DatasetFormat::Tum;
  if (fs::is_directory(root / "results", ec) && has("traj.txt")) return DatasetFormat::Replica;
  if (has_frame_files(root)) return DatasetFormat::SevenScenes;
  throw std::runtime_error("no dataset found in " + root.string() +
                           ": looked for scene.json + rgb.txt (synth), rgb.txt + depth.txt (tum), results/ + traj.txt "
                           "(replica), frame-*.color.* or frame-*.pose.txt (7scenes)");
}

std::unique_ptr<Dataset> open_dataset(const fs::path& root_in, const DatasetOptions& options) {
  const fs::path root = normalised(root_in);
  DatasetFormat format = options.format;
  if (format == DatasetFormat::Auto) format = detect_dataset_format(root);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::runtime_error("dataset folder not found: " + root.string());
  if (!(options.max_time_difference > 0))
    throw std::invalid_argument("max_time_difference must be > 0 seconds");
  spdlog::debug("opening {} as {}", root.string(), to_string(format));
  switch (format) {
    case DatasetFormat::Tum:
    case DatasetFormat::Synth: return open_tum(root, options, format);
    case DatasetFormat::SevenScenes: return open_seven_scenes(root, options);
    case DatasetFormat::Replica: return open_replica(root, options);
    case DatasetFormat::Auto: break;
  }
  throw std::logic_error("open_dataset: unhandled format");
}

}  // namespace rrg::io
