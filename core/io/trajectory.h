#pragma once
// Trajectories in the TUM text format: one line per pose, "t tx ty tz qx qy qz qw", '#' comments.
// Poses are T_wc (camera -> world), metres, seconds.
#include <Eigen/Geometry>

#include <filesystem>
#include <vector>

namespace rrg::io {

struct StampedPose {
  double timestamp = 0.0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
};
using Trajectory = std::vector<StampedPose>;

// Throws std::runtime_error naming the file and line on a malformed line or a non-unit quaternion
// (|q| outside [0.9, 1.1]); quaternions are normalised on read.
Trajectory read_tum_trajectory(const std::filesystem::path& path);
// Full precision (timestamps to 1e-6 s, positions to 1e-9 m); atomic write.
void write_tum_trajectory(const std::filesystem::path& path, const Trajectory& trajectory);

}  // namespace rrg::io
