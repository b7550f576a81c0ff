#include "core/eval/observed_surface.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::eval {

ObservedSurface::ObservedSurface(std::span<const Eigen::Vector3f> points, double tolerance_m,
                                 std::span<const Eigen::Vector3f> normals)
    : points_(points.begin(), points.end()),
      normals_(normals.begin(), normals.end()),
      seen_(points.size(), 0),
      tolerance_m_(tolerance_m) {
  if (!(tolerance_m > 0.0) || !std::isfinite(tolerance_m))
    throw std::invalid_argument("observed surface: the depth tolerance must be a positive number of metres");
  if (!normals_.empty() && normals_.size() != points_.size())
    throw std::invalid_argument("observed surface: " + std::to_string(normals_.size()) + " normals for " +
                                std::to_string(points_.size()) + " points");
}

void ObservedSurface::observe(const DepthImage& depth, const Intrinsics& K, const Eigen::Isometry3d& T_wc) {
  if (depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument("observed surface: depth " + std::to_string(depth.width()) + "x" +
                                std::to_string(depth.height()) + " differs from the intrinsics' " +
                                std::to_string(K.width) + "x" + std::to_string(K.height));
  const Eigen::Isometry3f T_cw = T_wc.inverse().cast<float>();
  const Eigen::Vector3f eye = T_wc.translation().cast<float>();
  const bool facing_test = !normals_.empty();
  const auto n = static_cast<std::int64_t>(points_.size());
  const float tol = float(tolerance_m_);
#pragma omp parallel for schedule(static) if (n >= 16384)
  for (std::int64_t i = 0; i < n; ++i) {
    if (seen_[size_t(i)]) continue;
    if (facing_test && normals_[size_t(i)].dot(eye - points_[size_t(i)]) <= 0.0f) continue;  // its back
    const Eigen::Vector3f p = T_cw * points_[size_t(i)];
    if (!(p.z() > 0.0f)) continue;
    const Eigen::Vector2f uv = K.project(p);
    const int x = int(std::lround(uv.x())), y = int(std::lround(uv.y()));
    if (x < 0 || y < 0 || x >= K.width || y >= K.height) continue;
    const float z = depth(x, y);
    if (z > 0.0f && std::abs(z - p.z()) <= tol) seen_[size_t(i)] = 1;
  }
}

size_t ObservedSurface::observed() const {
  size_t k = 0;
  for (uint8_t s : seen_) k += s;
  return k;
}

std::vector<Eigen::Vector3f> ObservedSurface::observed_points() const {
  std::vector<Eigen::Vector3f> out;
  out.reserve(observed());
  for (size_t i = 0; i < points_.size(); ++i)
    if (seen_[i]) out.push_back(points_[i]);
  return out;
}

}  // namespace rrg::eval
