// Replica in the NICE-SLAM layout: results/frameNNNNNN.{jpg,png}, results/depthNNNNNN.png (scale
// 6553.5), traj.txt (one row-major 4x4 camera-to-world per line), cam_params.json here or above.
#include "core/io/calibration.h"
#include "core/io/frame_list_dataset.h"
#include "core/io/text_parse.h"

#include <spdlog/spdlog.h>

#include <cctype>
#include <fstream>
#include <map>
#include <stdexcept>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

constexpr float kReplicaDepthScale = 6553.5f;
constexpr double kFps = 30.0;

// "frame000012.jpg" with prefix "frame" -> 12; nullopt otherwise.
std::optional<long> number_after(const std::string& name, const std::string& prefix, std::initializer_list<const char*> exts) {
  if (!name.starts_with(prefix)) return std::nullopt;
  size_t i = prefix.size();
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  if (i == prefix.size()) return std::nullopt;
  const std::string ext = name.substr(i);
  for (const char* e : exts)
    if (ext == e) return std::stol(name.substr(prefix.size(), i - prefix.size()));
  return std::nullopt;
}

std::vector<Eigen::Isometry3d> read_traj(const fs::path& path, std::vector<bool>& valid) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::vector<Eigen::Isometry3d> poses;
  std::string line;
  for (size_t line_no = 1; std::getline(in, line); ++line_no) {
    const auto fields = split_fields(line);
    if (fields.empty() || fields[0][0] == '#') continue;
    const std::string where = path.string() + ":" + std::to_string(line_no);
    if (fields.size() != 16)
      throw std::runtime_error(where + ": expected 16 numbers (row-major 4x4), got " + std::to_string(fields.size()));
    double m[16];
    for (int k = 0; k < 16; ++k) {
      const auto v = parse_double(fields[k]);
      if (!v) throw std::runtime_error(where + ": '" + std::string(fields[k]) + "' is not a number");
      m[k] = *v;
    }
    const auto pose = rigid_from_rows(m, where);
    poses.push_back(pose.value_or(Eigen::Isometry3d::Identity()));
    valid.push_back(pose.has_value());
  }
  return poses;
}

}  // namespace

std::unique_ptr<Dataset> open_replica(const fs::path& root, const DatasetOptions& options) {
  const fs::path results = root / "results";
  std::map<long, fs::path> colors, depths;
  for (const auto& entry : fs::directory_iterator(results)) {
    const std::string name = entry.path().filename().string();
    if (const auto n = number_after(name, "frame", {".jpg", ".png"})) colors[*n] = entry.path();
    else if (const auto d = number_after(name, "depth", {".png"})) depths[*d] = entry.path();
  }
  FrameList list;
  list.format = DatasetFormat::Replica;
  list.root = root;
  std::optional<Calibration> calib;
  const fs::path parent = fs::absolute(root).lexically_normal().parent_path();
  for (const fs::path& p : {root / "cam_params.json", parent / "cam_params.json"})
    if (fs::exists(p)) {
      calib = read_cam_params_json(p);
      if (options.intrinsics) spdlog::warn("{} overrides --intrinsics", p.string());
      break;
    }
  const Intrinsics named = *named_intrinsics("replica");
  list.intrinsics = calib ? calib->intrinsics : options.intrinsics.value_or(named);
  const std::optional<float> file_scale = calib ? calib->depth_scale : std::nullopt;
  list.depth_scale = file_scale.value_or(options.depth_scale.value_or(kReplicaDepthScale));

  std::vector<bool> valid;
  const std::vector<Eigen::Isometry3d> traj = read_traj(root / "traj.txt", valid);
  for (const auto& [n, color] : colors) {
    const auto d = depths.find(n);
    if (d == depths.end()) {
      char name[32];
      std::snprintf(name, sizeof(name), "depth%06ld.png", n);
      throw std::runtime_error("missing file " + (results / name).string() + " for " + color.string());
    }
    if (size_t(n) >= traj.size())
      throw std::runtime_error((root / "traj.txt").string() + " has " + std::to_string(traj.size()) +
                               " poses, too few for " + color.string());
    FrameEntry e;
    e.timestamp = double(n) / kFps;
    e.color = color;
    e.depth = d->second;
    if (valid[size_t(n)]) e.T_wc = traj[size_t(n)];
    list.frames.push_back(std::move(e));
  }
  if (list.frames.empty()) throw std::runtime_error("Replica folder " + results.string() + " has no frameNNNNNN.jpg/png");
  if (depths.size() > colors.size())
    spdlog::warn("{}: {} depth images have no colour image", results.string(), depths.size() - colors.size());
  return std::make_unique<FrameListDataset>(std::move(list));
}

}  // namespace rrg::io
