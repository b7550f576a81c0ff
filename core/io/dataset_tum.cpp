// TUM RGB-D folders (rgb.txt, depth.txt, optional groundtruth.txt) and our synthetic layout, which
// is the same plus camera.json and extras (docs/datasets.md).
#include "core/io/calibration.h"
#include "core/io/frame_list_dataset.h"
#include "core/io/text_parse.h"
#include "core/io/tum_association.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace rrg::io {
namespace {

namespace fs = std::filesystem;

constexpr float kTumDepthScale = 5000.0f;

struct ListEntry {
  double timestamp;
  fs::path path;
};

// rgb.txt / depth.txt: "timestamp path" lines, '#' comments; paths relative to the folder.
std::vector<ListEntry> read_file_list(const fs::path& list, const fs::path& root) {
  std::ifstream in(list);
  if (!in) throw std::runtime_error("cannot open " + list.string());
  std::vector<ListEntry> entries;
  std::string line;
  for (size_t line_no = 1; std::getline(in, line); ++line_no) {
    const auto fields = split_fields(line);
    if (fields.empty() || fields[0][0] == '#') continue;
    const auto t = fields.size() >= 2 ? parse_double(fields[0]) : std::nullopt;
    if (!t || !std::isfinite(*t))
      throw std::runtime_error(list.string() + ":" + std::to_string(line_no) + ": expected 'timestamp path', got '" +
                               line + "'");
    const fs::path p{std::string(fields[1])};
    entries.push_back({*t, p.is_absolute() ? p : root / p});
  }
  if (in.bad()) throw std::runtime_error("error reading " + list.string());
  return entries;
}

// The folder's own name, also for "path/" and ".".
std::string folder_name(const fs::path& root) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(root, ec), ec);
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().string();
}

// camera.json > --intrinsics > freiburg1/2/3 in the folder name > error.
Intrinsics tum_intrinsics(const fs::path& root, const DatasetOptions& options, std::optional<float>& file_scale) {
  const fs::path camera_json = root / "camera.json";
  if (fs::exists(camera_json)) {
    const Calibration c = read_camera_json(camera_json);
    if (options.intrinsics) spdlog::warn("{} overrides --intrinsics", camera_json.string());
    file_scale = c.depth_scale;
    return c.intrinsics;
  }
  if (options.intrinsics) return *options.intrinsics;
  const std::string name = folder_name(root);
  for (const char* fr : {"freiburg1", "freiburg2", "freiburg3"})
    if (name.find(fr) != std::string::npos) return *named_intrinsics(fr);
  throw std::runtime_error("no calibration for TUM folder " + root.string() +
                           ": no camera.json and the folder name has no freiburg1/2/3; pass --intrinsics fx,fy,cx,cy "
                           "(or a name: freiburg1|freiburg2|freiburg3|7scenes|replica)");
}

}  // namespace

std::unique_ptr<Dataset> open_tum(const fs::path& root, const DatasetOptions& options, DatasetFormat format) {
  FrameList list;
  list.format = format;
  list.root = root;
  const std::vector<ListEntry> rgb = read_file_list(root / "rgb.txt", root);
  const std::vector<ListEntry> depth = read_file_list(root / "depth.txt", root);
  std::vector<double> rgb_t, depth_t;
  for (const auto& e : rgb) rgb_t.push_back(e.timestamp);
  for (const auto& e : depth) depth_t.push_back(e.timestamp);
  const auto pairs = associate_stamps(rgb_t, depth_t, options.max_time_difference);
  if (pairs.empty())
    throw std::runtime_error("TUM folder " + root.string() + ": no rgb.txt / depth.txt pairs within " +
                             std::to_string(options.max_time_difference) + " s (" + std::to_string(rgb.size()) +
                             " colour, " + std::to_string(depth.size()) + " depth entries)");
  if (pairs.size() < rgb.size())
    spdlog::info("{}: {} of {} colour frames have a depth frame within {} s", root.string(), pairs.size(), rgb.size(),
                 options.max_time_difference);

  std::optional<float> file_scale;
  list.intrinsics = tum_intrinsics(root, options, file_scale);
  if (file_scale && options.depth_scale && *options.depth_scale != *file_scale)
    spdlog::warn("{} gives depth scale {}, overriding --depth-scale {}", (root / "camera.json").string(), *file_scale,
                 *options.depth_scale);
  list.depth_scale = file_scale.value_or(options.depth_scale.value_or(kTumDepthScale));

  Trajectory gt;
  if (fs::exists(root / "groundtruth.txt")) {
    gt = read_tum_trajectory(root / "groundtruth.txt");
    std::sort(gt.begin(), gt.end(), [](const auto& x, const auto& y) { return x.timestamp < y.timestamp; });
  }
  std::vector<double> gt_t;
  for (const auto& p : gt) gt_t.push_back(p.timestamp);

  for (const auto& [i, j] : pairs) {
    FrameEntry f;
    f.timestamp = rgb[i].timestamp;
    f.color = rgb[i].path;
    f.depth = depth[j].path;
    if (const auto k = nearest_stamp(gt_t, f.timestamp, options.max_time_difference)) f.T_wc = gt[*k].T_wc;
    list.frames.push_back(std::move(f));
  }
  return std::make_unique<FrameListDataset>(std::move(list));
}

}  // namespace rrg::io
