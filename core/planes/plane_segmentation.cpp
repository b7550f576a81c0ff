#include "core/planes/plane_segmentation.h"

#include "core/planes/plane_cells.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace rrg {

using planes_detail::CellGrid;

void PlaneSegmentationParams::validate() const {
  auto need = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("PlaneSegmentationParams: ") + what);
  };
  need(cell_size == 0 || cell_size >= 3, "cell_size must be 0 (auto) or >= 3");
  need(min_valid_ratio > 0 && min_valid_ratio <= 1, "min_valid_ratio must be in (0, 1]");
  need(sigma_min > 0 && sigma_k >= 0, "sigma_min must be > 0 and sigma_k >= 0");
  need(noise.valid() && planar_sigmas > 0, "noise_a, noise_b must be finite and >= 0 and planar_sigmas > 0");
  need(jump_ratio > 0, "jump_ratio must be > 0");
  need(histogram_bins >= 1, "histogram_bins must be >= 1");
  need(grow_angle_deg > 0 && grow_angle_deg < 90, "grow_angle_deg must be in (0, 90)");
  need(merge_angle_deg > 0 && merge_angle_deg < 90, "merge_angle_deg must be in (0, 90)");
  need(grow_distance_sigmas > 0 && refine_distance_sigmas > 0, "distance sigmas must be > 0");
  need(min_grow_distance >= 0 && min_refine_distance >= 0 && merge_distance >= 0, "distances must be >= 0");
  need(min_region_cells >= 1, "min_region_cells must be >= 1");
  need(min_plane_pixels >= 0, "min_plane_pixels must be >= 0");
}

std::string PlaneSegmentationParams::to_string() const {
  return fmt::format("cell {} px, noise {} + {} (z - {})^2 m, planar {} noise sigma, "
                     "sigma max({} m, {} z^2), grow {} deg / {} sigma, merge {} deg / {} m, "
                     "refine {} sigma, min region {} cells",
                     cell_size, noise.a, noise.b, noise.z0, planar_sigmas, sigma_min, sigma_k,
                     grow_angle_deg, grow_distance_sigmas, merge_angle_deg,
                     merge_distance, refine_distance_sigmas, min_region_cells);
}

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
float cos_deg(float deg) { return std::cos(deg * kPi / 180.0f); }

// Step 2: histogram-seeded region growing over planar cells. Returns the region of every cell
// (-1 = none) and the number of regions.
int grow_regions(const CellGrid& g, const PlaneSegmentationParams& p, std::vector<int>& region) {
  const int bins = p.histogram_bins;
  const size_t n = g.planar.size();
  std::vector<int> bin_of(n, -1);
  std::vector<int> count(size_t(bins) * bins, 0);
  for (size_t c = 0; c < n; ++c) {
    if (!g.planar[c]) continue;
    const Eigen::Vector3f& nc = g.fits[c].plane.n;
    const float polar = std::acos(std::clamp(-nc.z(), -1.0f, 1.0f));           // [0, π]
    const float azimuth = std::atan2(nc.y(), nc.x()) + kPi;                      // [0, 2π]
    const int bp = std::min(bins - 1, int(polar / kPi * float(bins)));
    const int ba = std::min(bins - 1, int(azimuth / (2 * kPi) * float(bins)));
    bin_of[c] = bp * bins + ba;
    ++count[size_t(bin_of[c])];
  }
  region.assign(n, -1);
  std::vector<uint8_t> used(n, 0);
  // Per bin, its cells by increasing MSE, and a cursor past the used ones: O(1) seed lookup.
  std::vector<std::vector<int>> by_bin(count.size());
  for (size_t c = 0; c < n; ++c)
    if (bin_of[c] >= 0) by_bin[size_t(bin_of[c])].push_back(int(c));
  for (auto& cells : by_bin)
    std::sort(cells.begin(), cells.end(), [&](int a, int b) { return g.fits[size_t(a)].mse < g.fits[size_t(b)].mse; });
  std::vector<size_t> cursor(count.size(), 0);
  const float cos_grow = cos_deg(p.grow_angle_deg);
  int regions = 0;
  std::vector<int> members;
  std::deque<int> queue;
  while (true) {
    const auto best = std::max_element(count.begin(), count.end());
    if (best == count.end() || *best == 0) break;
    const int bin = int(best - count.begin());
    auto& cells = by_bin[size_t(bin)];  // the bin's unused cell with the lowest MSE
    size_t& at = cursor[size_t(bin)];
    while (used[size_t(cells[at])]) ++at;
    const int seed = cells[at];
    // Neighbours are compared with the region's plane, refitted to the pooled moments of its cells
    // each time the region doubles: a lone cell's normal scatters by degrees under sensor noise.
    Plane sp = g.fits[size_t(seed)].plane;
    PlaneMoments pooled;
    size_t refit_at = 2;
    members.clear();
    queue.assign(1, seed);
    used[size_t(seed)] = 1;
    while (!queue.empty()) {
      const int c = queue.front();
      queue.pop_front();
      members.push_back(c);
      pooled.merge(g.moments[size_t(c)]);
      if (members.size() == refit_at) {
        const PlaneFit f = fit_plane(pooled);
        if (f.valid) sp = f.plane;
        refit_at *= 2;
      }
      --count[size_t(bin_of[size_t(c)])];
      const int cx = c % g.nx, cy = c / g.nx;
      const int nbs[4][2] = {{cx - 1, cy}, {cx + 1, cy}, {cx, cy - 1}, {cx, cy + 1}};
      for (const auto& nb : nbs) {
        if (nb[0] < 0 || nb[1] < 0 || nb[0] >= g.nx || nb[1] >= g.ny) continue;
        const int q = g.index(nb[0], nb[1]);
        if (used[size_t(q)] || !g.planar[size_t(q)]) continue;
        const PlaneFit& f = g.fits[size_t(q)];
        const float tol = std::max(p.min_grow_distance, p.grow_distance_sigmas * p.sigma(f.centroid.z()));
        if (f.plane.n.dot(sp.n) < cos_grow || std::abs(sp.signed_distance(f.centroid)) > tol) continue;
        used[size_t(q)] = 1;
        queue.push_back(q);
      }
    }
    if (int(members.size()) < p.min_region_cells) continue;  // cells stay used, region dropped
    for (int c : members) region[size_t(c)] = regions;
    ++regions;
  }
  return regions;
}

int find_root(std::vector<int>& parent, int a) {
  while (parent[size_t(a)] != a) a = parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
  return a;
}

// Step 3: merges adjacent regions whose planes agree; returns the fit of every surviving region
// and rewrites `region` to compact ids.
std::vector<PlaneFit> merge_regions(const CellGrid& g, const PlaneSegmentationParams& p, int regions,
                                    std::vector<int>& region) {
  std::vector<PlaneMoments> moments(static_cast<size_t>(regions));
  for (size_t c = 0; c < region.size(); ++c)
    if (region[c] >= 0) moments[size_t(region[c])].merge(g.moments[c]);
  std::vector<PlaneFit> fits(static_cast<size_t>(regions));
  for (int r = 0; r < regions; ++r) fits[size_t(r)] = fit_plane(moments[size_t(r)]);
  std::vector<std::pair<int, int>> edges;
  for (int cy = 0; cy < g.ny; ++cy)
    for (int cx = 0; cx < g.nx; ++cx) {
      const int a = region[size_t(g.index(cx, cy))];
      if (a < 0) continue;
      if (cx + 1 < g.nx) {
        const int b = region[size_t(g.index(cx + 1, cy))];
        if (b >= 0 && b != a) edges.emplace_back(std::min(a, b), std::max(a, b));
      }
      if (cy + 1 < g.ny) {
        const int b = region[size_t(g.index(cx, cy + 1))];
        if (b >= 0 && b != a) edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<int> parent(static_cast<size_t>(regions));
  std::iota(parent.begin(), parent.end(), 0);
  const float cos_merge = cos_deg(p.merge_angle_deg);
  auto agree = [&](const PlaneFit& a, const PlaneFit& b) {
    if (!a.valid || !b.valid || a.plane.n.dot(b.plane.n) < cos_merge) return false;
    const float ta = p.merge_tolerance(a.centroid.z()), tb = p.merge_tolerance(b.centroid.z());
    return std::abs(a.plane.signed_distance(b.centroid)) < tb && std::abs(b.plane.signed_distance(a.centroid)) < ta;
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& [ea, eb] : edges) {
      const int a = find_root(parent, ea), b = find_root(parent, eb);
      if (a == b || !agree(fits[size_t(a)], fits[size_t(b)])) continue;
      const int keep = std::min(a, b), gone = std::max(a, b);
      parent[size_t(gone)] = keep;
      moments[size_t(keep)].merge(moments[size_t(gone)]);
      fits[size_t(keep)] = fit_plane(moments[size_t(keep)]);
      changed = true;
    }
  }
  std::vector<int> compact(static_cast<size_t>(regions), -1);
  std::vector<PlaneFit> out;
  for (int r = 0; r < regions; ++r)
    if (find_root(parent, r) == r) {
      compact[size_t(r)] = int(out.size());
      out.push_back(fits[size_t(r)]);
    }
  for (int& r : region)
    if (r >= 0) r = compact[size_t(find_root(parent, r))];
  return out;
}

// The candidate regions of every cell for pixel refinement: the regions of the cell and of its
// one-cell ring.
std::vector<std::vector<int>> candidate_regions(const CellGrid& g, const std::vector<int>& region) {
  std::vector<std::vector<int>> candidates(region.size());
  for (int cy = 0; cy < g.ny; ++cy)
    for (int cx = 0; cx < g.nx; ++cx) {
      const int r = region[size_t(g.index(cx, cy))];
      if (r < 0) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy;
          if (x < 0 || y < 0 || x >= g.nx || y >= g.ny) continue;
          auto& list = candidates[size_t(g.index(x, y))];
          if (std::find(list.begin(), list.end(), r) == list.end()) list.push_back(r);
        }
    }
  return candidates;
}

// Step 4: pixel-level refinement. Each pixel of a region's cells and of the one-cell ring around
// them takes the nearest candidate plane within the distance threshold.
Image<int> refine_pixels(const CellGrid& g, const Image<Eigen::Vector3f>& points, const PlaneSegmentationParams& p,
                         const std::vector<int>& region, const std::vector<PlaneFit>& fits) {
  const std::vector<std::vector<int>> candidates = candidate_regions(g, region);
  Image<int> label(points.width(), points.height(), -1);
#pragma omp parallel for schedule(dynamic, 8)
  for (int c = 0; c < int(region.size()); ++c) {
    const auto& list = candidates[size_t(c)];
    if (list.empty()) continue;
    const int x0 = g.x0(c % g.nx), y0 = g.y0(c / g.nx);
    const int x1 = std::min(x0 + g.size, points.width()), y1 = std::min(y0 + g.size, points.height());
    for (int v = y0; v < y1; ++v)
      for (int u = x0; u < x1; ++u) {
        const Eigen::Vector3f& pt = points(u, v);
        if (pt.z() <= 0.0f) continue;
        float best = p.refine_distance(pt.z());
        for (int r : list) {
          const float d = std::abs(fits[size_t(r)].plane.signed_distance(pt));
          if (d < best) {
            best = d;
            label(u, v) = r;
          }
        }
      }
  }
  return label;
}

// Step 4b: a sliver between real planes. Cells across a floor-wall crease pass the planarity test
// under sensor noise, and their in-between plane wins the pixels near the crease. Such a region
// keeps under half of its own cells' pixels, and nearly every pixel it wins (≥ 90 %) lies within the
// refinement distance of another candidate region's plane as well; a thin real plane, such as a
// frame standing out of a wall, wins pixels no other plane explains. Slivers leave `region` (set to
// -1); returns whether any did, so that the pixels are refined again without them.
bool drop_slivers(const CellGrid& g, const Image<Eigen::Vector3f>& points, const PlaneSegmentationParams& p,
                  const Image<int>& label, const std::vector<PlaneFit>& fits, std::vector<int>& region) {
  const std::vector<std::vector<int>> candidates = candidate_regions(g, region);  // as refinement used
  std::vector<int64_t> own(fits.size(), 0), kept(fits.size(), 0), won(fits.size(), 0), shared(fits.size(), 0);
  for (int c = 0; c < int(region.size()); ++c) {
    const int r = region[size_t(c)];
    const int x0 = g.x0(c % g.nx), y0 = g.y0(c / g.nx);
    for (int v = y0; v < std::min(y0 + g.size, points.height()); ++v)
      for (int u = x0; u < std::min(x0 + g.size, points.width()); ++u) {
        const Eigen::Vector3f& pt = points(u, v);
        if (pt.z() <= 0.0f) continue;
        const int l = label(u, v);
        if (r >= 0) {
          ++own[size_t(r)];
          kept[size_t(r)] += l == r ? 1 : 0;
        }
        if (l < 0) continue;
        ++won[size_t(l)];
        const float tol = p.refine_distance(pt.z());
        for (int q : candidates[size_t(c)])
          if (q != l && std::abs(fits[size_t(q)].plane.signed_distance(pt)) < tol) {
            ++shared[size_t(l)];
            break;
          }
      }
  }
  bool any = false;
  for (int& r : region)
    if (r >= 0 && 2 * kept[size_t(r)] < own[size_t(r)] && 10 * shared[size_t(r)] >= 9 * won[size_t(r)]) {
      r = -1;
      any = true;
    }
  return any;
}

}  // namespace

PlaneSegmentation segment_planes(const DepthImage& depth, const Intrinsics& K, const PlaneSegmentationParams& params) {
  params.validate();
  if (depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument(fmt::format("segment_planes: depth is {}x{} but the intrinsics are {}x{}",
                                            depth.width(), depth.height(), K.width, K.height));
  const Image<Eigen::Vector3f> points = planes_detail::organised_points(depth, K);
  const CellGrid grid = planes_detail::fit_cells(points, params);
  std::vector<int> region;
  const int grown = grow_regions(grid, params, region);
  const std::vector<PlaneFit> fits = merge_regions(grid, params, grown, region);
  Image<int> label = refine_pixels(grid, points, params, region, fits);
  if (drop_slivers(grid, points, params, label, fits, region))
    label = refine_pixels(grid, points, params, region, fits);

  // Refit every plane to its pixels; drop the small ones; order by size.
  std::vector<PlaneMoments> moments(fits.size());
  for (size_t i = 0; i < label.size(); ++i)
    if (label[i] >= 0) moments[size_t(label[i])].add(points[i]);
  const int64_t min_pixels =
      params.min_plane_pixels > 0 ? params.min_plane_pixels : int64_t(2) * grid.size * grid.size;
  std::vector<int> order;
  for (size_t r = 0; r < fits.size(); ++r)
    if (moments[r].count() >= min_pixels) order.push_back(int(r));
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return moments[size_t(a)].count() > moments[size_t(b)].count(); });
  std::vector<int> new_id(fits.size(), 0);
  PlaneSegmentation out;
  out.cells_x = grid.nx;
  out.cells_y = grid.ny;
  out.planar_cells = int(std::count(grid.planar.begin(), grid.planar.end(), uint8_t(1)));
  for (int r : order) {
    const PlaneFit f = fit_plane(moments[size_t(r)]);
    if (!f.valid) continue;
    LocalPlane lp;
    lp.id = int(out.planes.size()) + 1;
    lp.plane = f.plane;
    lp.centroid = f.centroid;
    lp.pixels = moments[size_t(r)].count();
    lp.rms = std::sqrt(f.mse);
    lp.same_plane_distance = params.merge_tolerance(f.centroid.z());
    lp.planar_rms = params.planar_rms(f.centroid.z());
    new_id[size_t(r)] = lp.id;
    out.planes.push_back(lp);
  }
  out.labels = LabelImage(depth.width(), depth.height(), 0);
  for (size_t i = 0; i < label.size(); ++i)
    if (label[i] >= 0) out.labels[i] = uint16_t(new_id[size_t(label[i])]);
  return out;
}

}  // namespace rrg
