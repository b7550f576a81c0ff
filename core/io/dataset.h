#pragma once
// One interface for every RGB-D sequence we read: TUM RGB-D, 7-Scenes/3DMatch, Replica (NICE-SLAM
// layout) and our synthetic layout (TUM plus extras, see docs/datasets.md). Frames load lazily;
// intrinsics and depth scale come from a file in the folder when present, else from the options.
// Synth extras (labels, reflection masks, plane ids): core/io/synth_layout.h.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/io/trajectory.h"

#include <Eigen/Geometry>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rrg::io {

enum class DatasetFormat { Auto, Tum, SevenScenes, Replica, Synth };
DatasetFormat parse_dataset_format(const std::string& name);  // "tum|7scenes|replica|synth|auto"
std::string to_string(DatasetFormat format);

struct DatasetOptions {
  DatasetFormat format = DatasetFormat::Auto;
  // Used when the folder has no calibration file (camera.json, camera-intrinsics.txt,
  // cam_params.json); a calibration file wins, with a warning.
  std::optional<Intrinsics> intrinsics;   // --intrinsics fx,fy,cx,cy or a name (freiburg1|2|3, replica, 7scenes)
  std::optional<float> depth_scale;       // --depth-scale S (depth units per metre)
  double max_time_difference = 0.02;      // TUM association, seconds (as associate.py)
};

// Adds --format, --intrinsics, --depth-scale to a command that reads a dataset. The intrinsics
// string is parsed when the command runs (parse_intrinsics), so errors name the flag.
struct DatasetFlags {
  std::string format = "auto";
  std::string intrinsics;
  float depth_scale = 0.0f;
  DatasetOptions to_options() const;  // throws std::invalid_argument naming the bad flag value
};
void add_dataset_flags(CLI::App& app, DatasetFlags& flags);

// "fx,fy,cx,cy" or a named calibration: freiburg1, freiburg2, freiburg3 (TUM), 7scenes, replica.
// Width and height are left 0 when not implied; the dataset fills them from the first image.
Intrinsics parse_intrinsics(const std::string& text);

struct Frame {
  size_t index = 0;
  double timestamp = 0.0;
  ColorImage color;                          // C_gt, float RGB [0,1]
  DepthImage depth;                          // D_gt, metres, 0 = invalid, registered to colour
  std::optional<Eigen::Isometry3d> T_wc_gt;  // ground-truth / reference pose when the dataset has one
  std::filesystem::path color_path, depth_path;
};

class Dataset {
 public:
  virtual ~Dataset() = default;
  virtual DatasetFormat format() const = 0;
  virtual size_t size() const = 0;
  virtual const Intrinsics& intrinsics() const = 0;  // width/height always set
  virtual float depth_scale() const = 0;             // stored units per metre
  virtual bool has_ground_truth() const = 0;
  virtual Frame load(size_t index) const = 0;        // throws naming the missing/bad file
  // Ground-truth trajectory for the frames that have one (TUM format), empty when none.
  virtual Trajectory ground_truth() const = 0;
  virtual const std::filesystem::path& root() const = 0;
};

// Detects the format when options.format is Auto; throws std::runtime_error naming what is missing.
std::unique_ptr<Dataset> open_dataset(const std::filesystem::path& root,
                                      const DatasetOptions& options = {});
DatasetFormat detect_dataset_format(const std::filesystem::path& root);

}  // namespace rrg::io
