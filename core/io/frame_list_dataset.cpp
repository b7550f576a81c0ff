#include "core/io/frame_list_dataset.h"

#include "core/io/calibration.h"
#include "core/io/image_io.h"

#include <Eigen/SVD>

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::io {

namespace fs = std::filesystem;

void require_file(const fs::path& path, const std::string& listed_by) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw std::runtime_error("missing file " + path.string() + " (listed by " + listed_by + ")");
}

std::optional<Eigen::Isometry3d> rigid_from_rows(const double (&m)[16], const std::string& where) {
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = m[4 * r + c];
  if (!T.allFinite()) return std::nullopt;
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double last = (T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff();
  if (ortho > 1e-2 || last > 1e-6 || R.determinant() < 0)
    throw std::runtime_error(where + ": not a rigid camera-to-world transform (rotation error " +
                             std::to_string(ortho) + ", last row error " + std::to_string(last) + ")");
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  // Nearest rotation (polar decomposition): KinectFusion-style files store R only to ~1e-4.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  iso.linear() = svd.matrixU() * svd.matrixV().transpose();
  iso.translation() = T.topRightCorner<3, 1>();
  return iso;
}

FrameListDataset::FrameListDataset(FrameList list) : list_(std::move(list)) {
  if (list_.frames.empty()) throw std::runtime_error("dataset " + list_.root.string() + " has no frames");
  if (!(list_.depth_scale > 0.0f) || !std::isfinite(list_.depth_scale))
    throw std::invalid_argument("dataset " + list_.root.string() + ": depth scale must be > 0");
  const std::string by = to_string(list_.format) + " dataset " + list_.root.string();
  for (const FrameEntry& f : list_.frames) {
    require_file(f.color, by);
    require_file(f.depth, by);
  }
  Intrinsics& K = list_.intrinsics;
  if (!(K.fx > 0 && K.fy > 0)) throw std::invalid_argument("dataset " + list_.root.string() + ": intrinsics missing");
  if (K.width <= 0 || K.height <= 0) {
    const Eigen::Vector2i size = image_size(list_.frames.front().color);
    K.width = size.x();
    K.height = size.y();
  }
}

bool FrameListDataset::has_ground_truth() const {
  for (const FrameEntry& f : list_.frames)
    if (f.T_wc) return true;
  return false;
}

Trajectory FrameListDataset::ground_truth() const {
  Trajectory t;
  for (const FrameEntry& f : list_.frames)
    if (f.T_wc) t.push_back({f.timestamp, *f.T_wc});
  return t;
}

Frame FrameListDataset::load(size_t index) const {
  if (index >= list_.frames.size())
    throw std::out_of_range("frame " + std::to_string(index) + " requested from a dataset of " +
                            std::to_string(list_.frames.size()) + " frames (" + list_.root.string() + ")");
  const FrameEntry& e = list_.frames[index];
  Frame f;
  f.index = index;
  f.timestamp = e.timestamp;
  f.T_wc_gt = e.T_wc;
  f.color_path = e.color;
  f.depth_path = e.depth;
  f.color = read_color(e.color);
  const Image<uint16_t> raw = read_depth_raw(e.depth);
  if (raw.width() != f.color.width() || raw.height() != f.color.height())
    throw std::runtime_error("colour " + e.color.string() + " is " + std::to_string(f.color.width()) + "x" +
                             std::to_string(f.color.height()) + " but depth " + e.depth.string() + " is " +
                             std::to_string(raw.width()) + "x" + std::to_string(raw.height()));
  const Intrinsics& K = list_.intrinsics;
  if (f.color.width() != K.width || f.color.height() != K.height)
    throw std::runtime_error("colour " + e.color.string() + " is " + std::to_string(f.color.width()) + "x" +
                             std::to_string(f.color.height()) + " but the intrinsics are for " +
                             std::to_string(K.width) + "x" + std::to_string(K.height));
  f.depth = DepthImage(raw.width(), raw.height());
  for (size_t i = 0; i < raw.size(); ++i) {  // D = stored / scale, as read_depth
    const uint16_t v = raw[i];
    f.depth[i] = (list_.invalid_depth && v == *list_.invalid_depth) ? 0.0f : float(v) / list_.depth_scale;
  }
  return f;
}

}  // namespace rrg::io
