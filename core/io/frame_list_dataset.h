#pragma once
// Internal to core/io: the one Dataset implementation. Every format reader builds a list of
// (timestamp, colour file, depth file, optional pose) and the calibration, and this class loads
// frames from it on demand. Format readers: open_tum (TUM and synth), open_seven_scenes,
// open_replica.
#include "core/io/dataset.h"

#include <cstdint>

namespace rrg::io {

struct FrameEntry {
  double timestamp = 0.0;
  std::filesystem::path color, depth;
  std::optional<Eigen::Isometry3d> T_wc;
};

struct FrameList {
  DatasetFormat format = DatasetFormat::Auto;
  std::filesystem::path root;
  Intrinsics intrinsics;                   // width/height may be 0: filled from the first colour image
  float depth_scale = 0.0f;
  std::optional<uint16_t> invalid_depth;   // a stored value meaning "no depth" besides 0 (7-Scenes: 65535)
  std::vector<FrameEntry> frames;
};

class FrameListDataset final : public Dataset {
 public:
  // Checks every listed file exists (naming the first missing one), fills the image size.
  explicit FrameListDataset(FrameList list);

  DatasetFormat format() const override { return list_.format; }
  size_t size() const override { return list_.frames.size(); }
  const Intrinsics& intrinsics() const override { return list_.intrinsics; }
  float depth_scale() const override { return list_.depth_scale; }
  bool has_ground_truth() const override;
  Frame load(size_t index) const override;
  Trajectory ground_truth() const override;
  const std::filesystem::path& root() const override { return list_.root; }

 private:
  FrameList list_;
};

// Format readers (dataset_tum.cpp, dataset_7scenes.cpp, dataset_replica.cpp). `format` is Tum or
// Synth for open_tum (the synth layout is read as TUM).
std::unique_ptr<Dataset> open_tum(const std::filesystem::path& root, const DatasetOptions& options,
                                  DatasetFormat format);
std::unique_ptr<Dataset> open_seven_scenes(const std::filesystem::path& root, const DatasetOptions& options);
std::unique_ptr<Dataset> open_replica(const std::filesystem::path& root, const DatasetOptions& options);

// Helpers shared by the readers.
// Throws naming `path` (and who listed it) when the file does not exist.
void require_file(const std::filesystem::path& path, const std::string& listed_by);
// A 4x4 camera-to-world matrix (row major) -> isometry with the rotation re-orthonormalised;
// nullopt when a value is not finite (datasets mark lost frames with inf/nan); throws naming
// `where` when the matrix is not a rigid transform.
std::optional<Eigen::Isometry3d> rigid_from_rows(const double (&m)[16], const std::string& where);

}  // namespace rrg::io
