#include "core/planes/plane_cells.h"

#include <algorithm>
#include <cmath>

namespace rrg::planes_detail {

Image<Eigen::Vector3f> organised_points(const DepthImage& depth, const Intrinsics& K) {
  Image<Eigen::Vector3f> points(depth.width(), depth.height(), Eigen::Vector3f::Zero());
#pragma omp parallel for schedule(static)
  for (int v = 0; v < depth.height(); ++v)
    for (int u = 0; u < depth.width(); ++u) {
      const float z = depth(u, v);
      if (z > 0.0f && std::isfinite(z)) points(u, v) = K.unproject(float(u), float(v), z);
    }
  return points;
}

namespace {

// CAPE's discontinuity check: along the middle row and column of a cell, no jump between
// consecutive valid depths larger than ratio·z.
bool has_depth_jump(const Image<Eigen::Vector3f>& points, int x0, int y0, int x1, int y1, float ratio) {
  auto scan = [&](int xa, int ya, int dx, int dy, int n) {
    float prev = 0.0f;
    for (int i = 0; i < n; ++i) {
      const float z = points(xa + i * dx, ya + i * dy).z();
      if (z <= 0.0f) continue;
      if (prev > 0.0f && std::abs(z - prev) > ratio * std::min(z, prev)) return true;
      prev = z;
    }
    return false;
  };
  const int ym = (y0 + y1) / 2, xm = (x0 + x1) / 2;
  return scan(x0, ym, 1, 0, x1 - x0) || scan(xm, y0, 0, 1, y1 - y0);
}

}  // namespace

CellGrid fit_cells(const Image<Eigen::Vector3f>& points, const PlaneSegmentationParams& params) {
  CellGrid g;
  g.size = params.cell_size > 0 ? params.cell_size : std::max(4, points.width() / 40);
  g.nx = (points.width() + g.size - 1) / g.size;
  g.ny = (points.height() + g.size - 1) / g.size;
  const size_t n = size_t(g.nx) * size_t(g.ny);
  g.moments.assign(n, {});
  g.fits.assign(n, {});
  g.planar.assign(n, 0);
  g.depth.assign(n, 0.0f);
#pragma omp parallel for schedule(dynamic, 4)
  for (int c = 0; c < int(n); ++c) {
    const int cx = c % g.nx, cy = c / g.nx;
    const int x0 = g.x0(cx), y0 = g.y0(cy);
    const int x1 = std::min(x0 + g.size, points.width()), y1 = std::min(y0 + g.size, points.height());
    PlaneMoments& m = g.moments[size_t(c)];
    for (int v = y0; v < y1; ++v)
      for (int u = x0; u < x1; ++u)
        if (points(u, v).z() > 0.0f) m.add(points(u, v));
    const int64_t total = int64_t(x1 - x0) * (y1 - y0);
    if (m.count() < 3 || float(m.count()) < params.min_valid_ratio * float(total)) continue;
    const PlaneFit fit = fit_plane(m);
    g.fits[size_t(c)] = fit;
    g.depth[size_t(c)] = fit.centroid.z();
    if (!fit.valid) continue;
    if (std::sqrt(fit.mse) > params.planar_rms(fit.centroid.z())) continue;
    if (has_depth_jump(points, x0, y0, x1, y1, params.jump_ratio)) continue;
    g.planar[size_t(c)] = 1;
  }
  return g;
}

}  // namespace rrg::planes_detail
