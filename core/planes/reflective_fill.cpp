#include "core/planes/reflective_fill.h"

#include "core/planes/plane_fit.h"

#include <Eigen/Geometry>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace rrg {

float ReflectiveFillParams::tolerance(float z) const {
  return std::max(min_tolerance, inlier_sigmas * noise.sigma(z));
}

void ReflectiveFillParams::validate() const {
  const auto fail = [](const char* field, const char* why) {
    throw std::invalid_argument(fmt::format("planes.fill.{} {}", field, why));
  };
  if (!(min_missing >= 0.0f && min_missing <= 1.0f)) fail("min_missing", "must be in [0, 1]");
  if (min_mask_pixels < 1) fail("min_mask_pixels", "must be >= 1");
  if (!(ring_fraction >= 0.0f && ring_fraction <= 1.0f)) fail("ring_fraction", "must be in [0, 1]");
  if (min_ring_px < 1) fail("min_ring_px", "must be >= 1");
  if (min_ring_points < 3) fail("min_ring_points", "must be >= 3");
  if (!(inlier_sigmas > 0.0f) || !std::isfinite(inlier_sigmas)) fail("inlier_sigmas", "must be > 0");
  if (!(min_tolerance > 0.0f) || !std::isfinite(min_tolerance)) fail("min_tolerance", "must be > 0");
  if (!noise.valid()) fail("noise", "(planes.segmentation.noise_a/b/z0) must be finite, a and b >= 0");
  if (!(min_inlier_ratio > 0.0f && min_inlier_ratio <= 1.0f)) fail("min_inlier_ratio", "must be in (0, 1]");
  if (min_sides < 1 || min_sides > 4) fail("min_sides", "must be 1..4");
  if (!(min_side_share >= 0.0f && min_side_share <= 0.25f)) fail("min_side_share", "must be in [0, 0.25]");
  if (!(min_region_share >= 0.0f && min_region_share < 1.0f)) fail("min_region_share", "must be in [0, 1)");
  if (!(same_surface_angle_deg >= 0.0f && same_surface_angle_deg < 90.0f))
    fail("same_surface_angle_deg", "must be in [0, 90)");
  if (!(same_surface_distance >= 0.0f) || !std::isfinite(same_surface_distance))
    fail("same_surface_distance", "must be >= 0");
  if (!(max_ray_angle_deg > 0.0f && max_ray_angle_deg < 90.0f)) fail("max_ray_angle_deg", "must be in (0, 90)");
  if (ransac_iterations < 1) fail("ransac_iterations", "must be >= 1");
  if (!(max_depth > 0.0f) || !std::isfinite(max_depth)) fail("max_depth", "must be > 0");
}

namespace {

struct Box {
  int x0, y0, x1, y1;  // inclusive
};

// Pixels within Chebyshev distance r of the mask, restricted to the mask's box grown by r
// (separable: a row pass, then a column pass, each a running count over a 2r + 1 window).
MaskImage dilate(const MaskImage& mask, const Box& b, int r) {
  const int w = mask.width(), h = mask.height();
  const int x0 = std::max(0, b.x0 - r), x1 = std::min(w - 1, b.x1 + r);
  const int y0 = std::max(0, b.y0 - r), y1 = std::min(h - 1, b.y1 + r);
  MaskImage rows(w, h, 0), out(w, h, 0);
  for (int y = b.y0; y <= b.y1; ++y) {
    int count = 0;  // mask pixels in [x − r, x + r]
    for (int x = x0 - r; x <= x1; ++x) {
      const int in = x + r, gone = x - r - 1;
      if (in >= 0 && in < w && mask(in, y)) ++count;
      if (gone >= 0 && gone < w && mask(gone, y)) --count;
      if (x >= x0) rows(x, y) = count > 0;
    }
  }
  for (int x = x0; x <= x1; ++x) {
    int count = 0;
    for (int y = y0 - r; y <= y1; ++y) {
      const int in = y + r, gone = y - r - 1;
      if (in >= 0 && in < h && rows(x, in)) ++count;
      if (gone >= 0 && gone < h && rows(x, gone)) --count;
      if (y >= y0) out(x, y) = count > 0;
    }
  }
  return out;
}

// The bounding box of a mask's pixels (empty, x1 < x0, when it has none) and their count.
Box mask_box(const MaskImage& mask, int64_t& pixels) {
  Box box{mask.width(), mask.height(), -1, -1};
  pixels = 0;
  for (int v = 0; v < mask.height(); ++v)
    for (int u = 0; u < mask.width(); ++u)
      if (mask(u, v)) {
        ++pixels;
        box = {std::min(box.x0, u), std::min(box.y0, v), std::max(box.x1, u), std::max(box.y1, v)};
      }
  return box;
}

// The ring's width around a mask of bounding box `box`: max(min_ring_px, ring_fraction · diagonal).
int ring_width(const Box& box, const ReflectiveFillParams& params) {
  const float diagonal = std::hypot(float(box.x1 - box.x0 + 1), float(box.y1 - box.y0 + 1));
  return std::max(params.min_ring_px, int(std::lround(params.ring_fraction * diagonal)));
}

struct RingPoint {
  Eigen::Vector3f p;
  int u, v;
  float tol;
};

// RANSAC over (a stride of) the points, then a least-squares refit to the inliers.
bool fit_points_plane(const std::vector<RingPoint>& ring, const ReflectiveFillParams& params, Plane& plane) {
  constexpr size_t kMaxScored = 1024;  // a stride of the ring scores the hypotheses; the refit takes all
  const size_t stride = std::max<size_t>(1, ring.size() / kMaxScored);
  std::mt19937 rng(0x5eedu);  // deterministic: the same frame gives the same fill
  std::uniform_int_distribution<size_t> pick(0, ring.size() - 1);
  Plane best;
  size_t best_count = 0;
  for (int it = 0; it < params.ransac_iterations; ++it) {
    const Eigen::Vector3f &a = ring[pick(rng)].p, &b = ring[pick(rng)].p, &c = ring[pick(rng)].p;
    Eigen::Vector3f n = (b - a).cross(c - a);
    const float len = n.norm();
    if (!(len > 1e-9f)) continue;
    n /= len;
    const Plane cand{n, -n.dot(a)};
    size_t count = 0;
    for (size_t i = 0; i < ring.size(); i += stride)
      if (std::abs(cand.signed_distance(ring[i].p)) < ring[i].tol) ++count;
    if (count > best_count) {
      best_count = count;
      best = cand;
    }
  }
  if (best_count < 3) return false;
  PlaneMoments m;
  for (const RingPoint& r : ring)
    if (std::abs(best.signed_distance(r.p)) < r.tol) m.add(r.p);
  const PlaneFit fit = fit_plane(m);  // normal towards the camera centre: d > 0
  if (!fit.valid) return false;
  plane = fit.plane;
  return true;
}

// How far apart two planes may lie and still be one surface for the fill: max(same_surface_distance,
// w + tol), w the width of a ring of ring_px pixels in metres at depth z and tol the inlier
// tolerance there (see own_surface_plane).
float surface_bound(int ring_px, float z, const Intrinsics& K, const ReflectiveFillParams& params) {
  const float ring_m = float(ring_px) * z / std::min(K.fx, K.fy);
  return std::max(params.same_surface_distance, ring_m + params.tolerance(z));
}

// The surface the sensor kept on a mask: a plane that at least 1 − min_missing of the mask's pixels
// lie on (within the inlier tolerance), and that is the ring's surface: normals within
// same_surface_angle_deg and the inliers' centroid within surface_bound of the ring's plane (the
// global plane table's geometric filter, 10° and 0.1 m, widened to the ring's width plus the
// tolerance where that is more). The ring places its plane no closer than that: across a crease (a
// floor's edge against the walls) the ring is a strip of wall r pixels wide, and a plane through
// that strip may lie anywhere in it, a tolerance beyond. Glass seen through shows the mirrored room,
// which is farther behind; lost glass has too little depth. Such a mask is kept, never filled.
bool own_surface_plane(const DepthImage& depth, const MaskImage& mask, const Box& box, int64_t mask_pixels, int ring_px,
                       const Intrinsics& K, const ReflectiveFillParams& params, const Plane& ring_plane, Plane& plane) {
  std::vector<RingPoint> points;
  for (int v = box.y0; v <= box.y1; ++v)
    for (int u = box.x0; u <= box.x1; ++u) {
      const float z = depth(u, v);
      if (!mask(u, v) || !(z > 0.0f) || !std::isfinite(z)) continue;
      points.push_back({z * K.unproject(float(u), float(v), 1.0f), u, v, params.tolerance(z)});
    }
  const float needed = (1.0f - params.min_missing) * float(mask_pixels);
  if (int64_t(points.size()) < params.min_ring_points || float(points.size()) < needed) return false;
  Plane own;
  if (!fit_points_plane(points, params, own)) return false;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  size_t inliers = 0;
  for (const RingPoint& p : points)
    if (std::abs(own.signed_distance(p.p)) < p.tol) {
      centroid += p.p;
      ++inliers;
    }
  if (float(inliers) < needed) return false;
  centroid /= float(inliers);
  if (own.n.dot(ring_plane.n) < std::cos(params.same_surface_angle_deg * float(M_PI) / 180.0f)) return false;
  if (!(std::abs(ring_plane.signed_distance(centroid)) <= surface_bound(ring_px, centroid.z(), K, params))) return false;
  plane = own;
  return true;
}

// Depth along the optical axis at which pixel (u, v)'s ray meets `plane` (camera frame) on its
// camera-facing side; 0 when it does not, meets it more obliquely than cos_max, or beyond max_depth.
float plane_depth(const Plane& plane, const Intrinsics& K, int u, int v, float cos_max, float max_depth) {
  const Eigen::Vector3f d = K.unproject(float(u), float(v), 1.0f);
  const float nd = plane.n.dot(d);  // < 0 when the ray meets the camera-facing side
  if (!(-nd >= cos_max * d.norm())) return 0.0f;
  const float z = -plane.d / nd;
  return z > 0.0f && z <= max_depth ? z : 0.0f;
}

// Depth d the sensor lost where the plane is at z: none, or behind the plane beyond the tolerance.
bool lost(float d, float z, const ReflectiveFillParams& params) {
  return !(d > 0.0f) || !std::isfinite(d) || (z > 0.0f && d > z + params.tolerance(z));
}

// Writes the plane rec.plane into the mask's lost pixels, and into the glass beyond the mask (a
// mask that stops short of it: ring pixels (`grown` less the mask) with depth behind the plane,
// reached from the mask through such pixels, 4-neighbours) when params.grow_beyond_mask; records
// them in rec (filled, beyond) and in `filled`.
void fill_mask_from_plane(DepthImage& depth, const MaskImage& mask, const Box& box, const MaskImage& grown,
                          const Intrinsics& K, const ReflectiveFillParams& params, ReflectiveFillMask& rec,
                          MaskImage& filled) {
  const int w = depth.width(), h = depth.height();
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  const auto z_at = [&](int u, int v) { return plane_depth(rec.plane, K, u, v, cos_max, params.max_depth); };
  if (params.grow_beyond_mask) {
    const auto glass = [&](int u, int v) {
      const float d = depth(u, v);
      if (!grown(u, v) || mask(u, v) || !(d > 0.0f) || !std::isfinite(d)) return false;
      const float z = z_at(u, v);
      return z > 0.0f && lost(d, z, params);
    };
    MaskImage seen(w, h, 0);
    std::vector<int32_t> stack;
    const auto visit = [&](int u, int v) {
      if (u < 0 || v < 0 || u >= w || v >= h || seen(u, v) || !glass(u, v)) return;
      seen(u, v) = 1;
      stack.push_back(v * w + u);
    };
    for (int v = box.y0; v <= box.y1; ++v)
      for (int u = box.x0; u <= box.x1; ++u)
        if (mask(u, v)) visit(u - 1, v), visit(u + 1, v), visit(u, v - 1), visit(u, v + 1);
    while (!stack.empty()) {
      const int32_t i = stack.back();
      stack.pop_back();
      rec.beyond.push_back(i);
      const int u = i % w, v = i / w;
      visit(u - 1, v), visit(u + 1, v), visit(u, v - 1), visit(u, v + 1);
    }
    std::sort(rec.beyond.begin(), rec.beyond.end());
  }
  for (int v = box.y0; v <= box.y1; ++v)
    for (int u = box.x0; u <= box.x1; ++u) {
      if (!mask(u, v)) continue;
      const float z = z_at(u, v);
      if (z > 0.0f && lost(depth(u, v), z, params)) {
        depth(u, v) = z;
        filled(u, v) = 1;
        ++rec.filled;
      }
    }
  for (const int32_t i : rec.beyond) {
    depth[size_t(i)] = z_at(i % w, i / w);
    filled[size_t(i)] = 1;
    ++rec.filled;
  }
}

}  // namespace

ReflectiveFillResult fill_reflective_depth(DepthImage& depth, std::span<const SemanticMask> masks, const Intrinsics& K,
                                           const ReflectiveFillParams& params) {
  params.validate();
  const int w = depth.width(), h = depth.height();
  if (K.width != w || K.height != h)
    throw std::invalid_argument(fmt::format("fill_reflective_depth: intrinsics {}x{} but depth {}x{}", K.width, K.height, w, h));
  for (const SemanticMask& m : masks)
    if (!m.mask.same_size(depth))
      throw std::invalid_argument(fmt::format("fill_reflective_depth: mask '{}' is {}x{}, depth {}x{}", m.label,
                                              m.mask.width(), m.mask.height(), w, h));
  ReflectiveFillResult out;
  out.filled = MaskImage(w, h, 0);
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  for (const SemanticMask& sm : masks) {
    if (!sm.reflective) continue;
    ReflectiveFillMask rec;
    rec.label = sm.label;
    rec.mask_index = size_t(&sm - masks.data());
    const Box box = mask_box(sm.mask, rec.pixels);
    const auto done = [&](std::string why) {
      rec.skipped = std::move(why);
      out.masks.push_back(std::move(rec));
    };
    if (rec.pixels < params.min_mask_pixels) {
      done("mask too small");
      continue;
    }
    // The ring and its valid depth, back-projected.
    const int r = ring_width(box, params);
    const MaskImage grown = dilate(sm.mask, box, r);
    std::vector<RingPoint> ring;
    for (int v = std::max(0, box.y0 - r); v <= std::min(h - 1, box.y1 + r); ++v)
      for (int u = std::max(0, box.x0 - r); u <= std::min(w - 1, box.x1 + r); ++u) {
        const float z = depth(u, v);
        if (!grown(u, v) || sm.mask(u, v) || !(z > 0.0f) || !std::isfinite(z)) continue;
        ring.push_back({z * K.unproject(float(u), float(v), 1.0f), u, v, params.tolerance(z)});
      }
    rec.ring_points = int64_t(ring.size());
    if (rec.ring_points < params.min_ring_points) {
      done("too little depth around the mask");
      continue;
    }
    if (!fit_points_plane(ring, params, rec.plane)) {
      done("no plane around the mask");
      continue;
    }
    rec.fitted = true;
    const auto z_at = [&](int u, int v) { return plane_depth(rec.plane, K, u, v, cos_max, params.max_depth); };
    // Ring points on the plane, in front of it (occluders) or behind it; the sides of the box the
    // inliers lie on (the one each is farthest outside of).
    std::array<int64_t, 4> side{0, 0, 0, 0};
    int64_t inliers = 0;
    for (const RingPoint& p : ring) {
      const float sd = rec.plane.signed_distance(p.p);  // > 0 on the camera's side
      if (std::abs(sd) < p.tol) {
        ++inliers;
        const std::array<int, 4> out_by{box.x0 - p.u, p.u - box.x1, box.y0 - p.v, p.v - box.y1};
        ++side[size_t(std::max_element(out_by.begin(), out_by.end()) - out_by.begin())];
      } else {
        ++(sd > 0.0f ? rec.in_front : rec.behind);
      }
    }
    rec.inlier_ratio = float(inliers) / float(rec.ring_points);
    for (const int64_t s : side) rec.sides += s > 0 && float(s) >= params.min_side_share * float(inliers);
    const auto count_missing = [&] {
      rec.missing = 0;
      for (int v = box.y0; v <= box.y1; ++v)
        for (int u = box.x0; u <= box.x1; ++u)
          if (sm.mask(u, v)) rec.missing += lost(depth(u, v), z_at(u, v), params);
    };
    count_missing();
    if (rec.inlier_ratio < params.min_inlier_ratio) {
      done(fmt::format("the depth around the mask is not planar ({:.2f} on the plane)", rec.inlier_ratio));
      continue;
    }
    if (rec.sides < params.min_sides) {
      done(fmt::format("the plane around the mask is seen on {} side(s)", rec.sides));
      continue;
    }
    // A mask about to be filled whose own depth is the ring's surface is kept (its plane and missing
    // then that surface's): the ring's plane is fitted to what borders the mask, and around a floor
    // that is the foot of the walls (a crease on two sides or more), a plane off the floor that
    // leaves it "behind". (A mask the ring's plane already keeps needs no second fit.)
    if (float(rec.missing) >= params.min_missing * float(rec.pixels) &&
        (rec.own_surface = own_surface_plane(depth, sm.mask, box, rec.pixels, r, K, params, rec.plane, rec.plane)))
      count_missing();
    if (rec.own_surface || float(rec.missing) < params.min_missing * float(rec.pixels)) {
      rec.kept = true;
      done("the sensor kept the surface");
      continue;
    }
    fill_mask_from_plane(depth, sm.mask, box, grown, K, params, rec, out.filled);
    out.pixels += rec.filled;
    if (rec.filled == 0) rec.skipped = "no pixel faces the plane";
    out.masks.push_back(std::move(rec));
  }
  return out;
}

void add_glass_beyond(const ReflectiveFillResult& result, std::span<SemanticMask> masks) {
  for (const ReflectiveFillMask& m : result.masks) {
    if (m.beyond.empty()) continue;
    if (m.mask_index >= masks.size() || m.beyond.back() >= int32_t(masks[m.mask_index].mask.size()))
      throw std::invalid_argument("add_glass_beyond: the masks are not those of the fill");
    for (const int32_t i : m.beyond) masks[m.mask_index].mask[size_t(i)] = 1;
  }
}

std::vector<FillRegion> fill_regions(const ReflectiveFillResult& result, std::span<const SemanticMask> masks,
                                     const Intrinsics& K, const Eigen::Isometry3f& T_wc, float cell) {
  if (!(cell > 0.0f)) throw std::invalid_argument("fill_regions: cell must be > 0");
  std::vector<FillRegion> out;
  for (const ReflectiveFillMask& m : result.masks) {
    if (m.filled == 0 || !m.fitted || m.from_region) continue;
    if (m.mask_index >= masks.size()) throw std::invalid_argument("fill_regions: the masks are not those of the fill");
    const MaskImage& mask = masks[m.mask_index].mask;
    if (mask.width() != K.width || mask.height() != K.height)
      throw std::invalid_argument("fill_regions: mask and intrinsics sizes differ");
    // The mask's pixels on the plane, world frame, every second one per axis: two pixels span less
    // than a 5 cm cell at indoor ranges, and the footprint is read with a one-cell dilation.
    // The glass filled beyond the mask as well, every pixel (a strip a few pixels wide).
    std::vector<Eigen::Vector3f> points;
    const auto add = [&](int u, int v) {
      const float z = plane_depth(m.plane, K, u, v, 0.0f, std::numeric_limits<float>::max());
      if (z > 0.0f) points.push_back(T_wc * (z * K.unproject(float(u), float(v), 1.0f)));
    };
    for (int v = 0; v < K.height; v += 2)
      for (int u = 0; u < K.width; u += 2)
        if (mask(u, v)) add(u, v);
    for (const int32_t i : m.beyond)
      if (i >= 0 && i < K.width * K.height) add(i % K.width, i / K.width);
    if (points.empty()) continue;
    FillRegion region;
    region.label = m.label;
    region.plane = m.plane.transformed(T_wc);
    region.footprint = Footprint(PlaneBasis::from_plane(region.plane, points.front()), cell);
    region.footprint.add_points(points);
    out.push_back(std::move(region));
  }
  return out;
}

namespace {

// The pixels [x0, x1] x [y0, y1] that a footprint dilated by one cell can cover from a camera
// (T_cw, K): the image of its bounding box grown by two cells (a cell reaches one past the points
// that made it, the dilation one more), a convex quad whose corners bound it when all are in front
// of the camera; the whole image otherwise. x1 < x0 when it is out of view.
Box footprint_window(const Footprint& fp, const Eigen::Isometry3f& T_cw, const Intrinsics& K) {
  const Box whole{0, 0, K.width - 1, K.height - 1};
  if (fp.box().empty) return whole;
  const float m = 2.0f * fp.cell_size();
  float u0 = std::numeric_limits<float>::max(), v0 = u0, u1 = -u0, v1 = -u0;
  for (int c = 0; c < 4; ++c) {
    const float x = (c & 1) ? fp.box().max.x() + m : fp.box().min.x() - m;
    const float y = (c & 2) ? fp.box().max.y() + m : fp.box().min.y() - m;
    const Eigen::Vector3f p = T_cw * (fp.basis().origin + x * fp.basis().u + y * fp.basis().v);
    if (!(p.z() > 1e-3f)) return whole;
    const Eigen::Vector2f uv = K.project(p);
    u0 = std::min(u0, uv.x()), u1 = std::max(u1, uv.x()), v0 = std::min(v0, uv.y()), v1 = std::max(v1, uv.y());
  }
  if (u1 < 0.0f || v1 < 0.0f || u0 > float(K.width - 1) || v0 > float(K.height - 1)) return {0, 0, -1, -1};
  return {std::max(0, int(std::floor(u0))), std::max(0, int(std::floor(v0))),
          std::min(K.width - 1, int(std::ceil(u1))), std::min(K.height - 1, int(std::ceil(v1)))};
}

// The centre of a footprint's bounding box, in the world frame (on its plane).
Eigen::Vector3f footprint_centre(const Footprint& fp) {
  const Eigen::Vector2f c = 0.5f * (fp.box().min + fp.box().max);
  return fp.basis().origin + c.x() * fp.basis().u + c.y() * fp.basis().v;
}

// The region of `label` that most of a mask's pixels (every second one per axis, `sampled` of them)
// meet at pose T_wc, their rays reaching its plane from the front within its footprint (`on` of
// them); nullptr when none does.
const FillRegion* region_under_mask(const MaskImage& mask, const Box& box, const std::string& label,
                                    std::span<const FillRegion> regions, const Intrinsics& K,
                                    const Eigen::Isometry3f& T_wc, const ReflectiveFillParams& params,
                                    int64_t& sampled, int64_t& on_best) {
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  const Eigen::Isometry3f T_cw = T_wc.inverse();
  sampled = on_best = 0;
  for (int v = box.y0; v <= box.y1; v += 2)
    for (int u = box.x0; u <= box.x1; u += 2) sampled += mask(u, v) != 0;
  const FillRegion* best = nullptr;
  for (const FillRegion& region : regions) {
    if (region.label != label) continue;
    const Plane pc = region.plane.transformed(T_cw);
    if (!(pc.d > 0.0f)) continue;  // seen from behind
    int64_t on = 0;
    for (int v = box.y0; v <= box.y1; v += 2)
      for (int u = box.x0; u <= box.x1; u += 2) {
        if (!mask(u, v)) continue;
        const float z = plane_depth(pc, K, u, v, cos_max, params.max_depth);
        on += z > 0.0f && region.footprint.covers(T_wc * (z * K.unproject(float(u), float(v), 1.0f)));
      }
    if (on > on_best) {
      on_best = on;
      best = &region;
    }
  }
  return best;
}

}  // namespace

bool same_surface(const FillRegion& carried, const FillRegion& fresh, const RegionMatch& match) {
  if (carried.label != fresh.label) return false;
  if (carried.footprint.cells() == 0 || fresh.footprint.cells() == 0) return false;
  if (carried.plane.n.dot(fresh.plane.n) < std::cos(match.max_normal_angle_deg * float(M_PI) / 180.0f)) return false;
  if (std::abs(carried.plane.signed_distance(footprint_centre(fresh.footprint))) > match.max_distance ||
      std::abs(fresh.plane.signed_distance(footprint_centre(carried.footprint))) > match.max_distance)
    return false;
  Footprint on_fresh(fresh.footprint.basis(), fresh.footprint.cell_size());
  on_fresh.merge(carried.footprint);
  return fresh.footprint.overlap_ratio(on_fresh) > match.min_overlap;
}

size_t merge_fill_regions(std::vector<FillRegion>& carried, std::vector<FillRegion> fresh, const RegionMatch& match) {
  std::erase_if(carried, [&](const FillRegion& old) {
    return std::any_of(fresh.begin(), fresh.end(), [&](const FillRegion& f) { return same_surface(old, f, match); });
  });
  const size_t kept = carried.size();
  for (FillRegion& f : fresh) carried.push_back(std::move(f));
  return kept;
}

ReflectiveFillResult fill_from_regions(DepthImage& depth, std::span<const FillRegion> regions, const Intrinsics& K,
                                       const Eigen::Isometry3f& T_wc, const ReflectiveFillParams& params) {
  params.validate();
  const int w = depth.width(), h = depth.height();
  if (K.width != w || K.height != h)
    throw std::invalid_argument(fmt::format("fill_from_regions: intrinsics {}x{} but depth {}x{}", K.width, K.height, w, h));
  ReflectiveFillResult out;
  out.filled = MaskImage(w, h, 0);
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  const Eigen::Isometry3f T_cw = T_wc.inverse();
  for (const FillRegion& region : regions) {
    ReflectiveFillMask rec;
    rec.label = region.label;
    rec.plane = region.plane.transformed(T_cw);  // camera frame
    rec.fitted = true;
    if (!(rec.plane.d > 0.0f)) {  // the camera is behind the surface
      rec.skipped = "seen from behind";
      out.masks.push_back(std::move(rec));
      continue;
    }
    const Box window = footprint_window(region.footprint, T_cw, K);
    if (window.x1 < window.x0) {
      rec.skipped = "out of view";
      out.masks.push_back(std::move(rec));
      continue;
    }
    for (int v = window.y0; v <= window.y1; ++v)
      for (int u = window.x0; u <= window.x1; ++u) {
        // The depth test first: most pixels keep theirs, and then need no footprint lookups.
        const float z = plane_depth(rec.plane, K, u, v, cos_max, params.max_depth);
        if (!(z > 0.0f) || !lost(depth(u, v), z, params)) continue;
        if (!region.footprint.covers(T_wc * (z * K.unproject(float(u), float(v), 1.0f)))) continue;
        depth(u, v) = z;
        out.filled(u, v) = 1;
        ++rec.filled;
      }
    rec.pixels = rec.missing = rec.filled;
    out.pixels += rec.filled;
    out.masks.push_back(std::move(rec));
  }
  return out;
}

int64_t fill_failed_masks_from_regions(DepthImage& depth, ReflectiveFillResult& result,
                                       std::span<const SemanticMask> masks, std::span<const FillRegion> regions,
                                       const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                                       const ReflectiveFillParams& params, MaskImage& written) {
  params.validate();
  const int w = depth.width(), h = depth.height();
  if (K.width != w || K.height != h || !written.same_size(depth) || !result.filled.same_size(depth))
    throw std::invalid_argument(fmt::format("fill_failed_masks_from_regions: intrinsics {}x{}, depth {}x{}, masks {}x{} and "
                                            "{}x{} differ", K.width, K.height, w, h, written.width(), written.height(),
                                            result.filled.width(), result.filled.height()));
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  const Eigen::Isometry3f T_cw = T_wc.inverse();
  int64_t total = 0;
  for (ReflectiveFillMask& rec : result.masks) {
    if (rec.filled > 0) continue;
    if (rec.mask_index >= masks.size() || !masks[rec.mask_index].mask.same_size(depth))
      throw std::invalid_argument("fill_failed_masks_from_regions: the masks are not those of the fill");
    const MaskImage& mask = masks[rec.mask_index].mask;
    int64_t pixels = 0;
    const Box box = mask_box(mask, pixels);
    if (pixels < params.min_mask_pixels) continue;
    int64_t sampled = 0, best_on = 0;
    const FillRegion* best = region_under_mask(mask, box, rec.label, regions, K, T_wc, params, sampled, best_on);
    if (!best || float(best_on) <= params.min_region_share * float(sampled)) continue;
    ReflectiveFillMask from_region = rec;
    from_region.plane = best->plane.transformed(T_cw);
    from_region.fitted = true;
    from_region.from_region = true;
    from_region.missing = 0;
    for (int v = box.y0; v <= box.y1; ++v)
      for (int u = box.x0; u <= box.x1; ++u)
        if (mask(u, v))
          from_region.missing += lost(depth(u, v), plane_depth(from_region.plane, K, u, v, cos_max, params.max_depth), params);
    if (float(from_region.missing) < params.min_missing * float(pixels)) continue;
    MaskImage fresh(w, h, 0);
    fill_mask_from_plane(depth, mask, box, dilate(mask, box, ring_width(box, params)), K, params, from_region, fresh);
    if (from_region.filled == 0) continue;
    for (size_t i = 0; i < fresh.size(); ++i)
      if (fresh[i]) written[i] = result.filled[i] = 1;
    from_region.skipped.clear();
    rec = std::move(from_region);
    result.pixels += rec.filled;
    total += rec.filled;
  }
  return total;
}

std::string describe(const ReflectiveFillMask& m) {
  return fmt::format("{} mask, {} px, {} missing{}: {}", m.label, m.pixels, m.missing,
                     m.own_surface ? " (of its own depth's plane)" : "",
                     m.skipped.empty() ? fmt::format("{} px filled", m.filled) : m.skipped);
}

size_t drop_refuted_regions(std::vector<FillRegion>& regions, const ReflectiveFillResult& result,
                            std::span<const SemanticMask> masks, const DepthImage& depth, const Intrinsics& K,
                            const Eigen::Isometry3f& T_wc, const ReflectiveFillParams& params) {
  params.validate();
  if (K.width != depth.width() || K.height != depth.height())
    throw std::invalid_argument(fmt::format("drop_refuted_regions: intrinsics {}x{} but depth {}x{}", K.width, K.height,
                                            depth.width(), depth.height()));
  const float cos_max = std::cos(params.max_ray_angle_deg * float(M_PI) / 180.0f);
  const Eigen::Isometry3f T_cw = T_wc.inverse();
  size_t dropped = 0;
  for (const ReflectiveFillMask& rec : result.masks) {
    if (!rec.kept) continue;
    if (rec.mask_index >= masks.size() || !masks[rec.mask_index].mask.same_size(depth))
      throw std::invalid_argument("drop_refuted_regions: the masks are not those of the fill");
    const MaskImage& mask = masks[rec.mask_index].mask;
    int64_t pixels = 0;
    const Box box = mask_box(mask, pixels);
    int64_t sampled = 0, on = 0;
    const FillRegion* region = region_under_mask(mask, box, rec.label, regions, K, T_wc, params, sampled, on);
    if (!region || float(on) <= params.min_region_share * float(sampled)) continue;
    // Where the region would write (the mask's pixels its footprint covers with depth lost against
    // its plane): the kept surface behind it by no more than surface_bound is that surface, which
    // the region misplaces; farther behind, the mask sees through the region's glass (a mask inside
    // the glass, whose ring is the room seen through it too), and the region stands.
    const Plane pc = region->plane.transformed(T_cw);
    std::vector<float> behind;
    double z_sum = 0.0;  // their depths, for the bound
    for (int v = box.y0; v <= box.y1; v += 2)
      for (int u = box.x0; u <= box.x1; u += 2) {
        if (!mask(u, v)) continue;
        const float z = plane_depth(pc, K, u, v, cos_max, params.max_depth);
        if (!(z > 0.0f) || !region->footprint.covers(T_wc * (z * K.unproject(float(u), float(v), 1.0f)))) continue;
        const float d = depth(u, v);
        if (d > 0.0f && std::isfinite(d) && lost(d, z, params)) {
          behind.push_back(-pc.signed_distance(d * K.unproject(float(u), float(v), 1.0f)));
          z_sum += d;
        }
      }
    if (behind.empty() || float(behind.size()) < params.min_missing * float(on)) continue;  // it writes little
    const auto mid = behind.begin() + ptrdiff_t(behind.size() / 2);
    std::nth_element(behind.begin(), mid, behind.end());
    const float z_mean = float(z_sum / double(behind.size()));
    if (!(*mid <= surface_bound(ring_width(box, params), z_mean, K, params))) continue;
    regions.erase(regions.begin() + (region - regions.data()));
    ++dropped;
  }
  return dropped;
}

void copy_filled_depth(const DepthImage& from, const MaskImage& filled, DepthImage& to) {
  if (!from.same_size(filled) || !from.same_size(to))
    throw std::invalid_argument(fmt::format("copy_filled_depth: sizes {}x{}, {}x{} and {}x{} differ", from.width(),
                                            from.height(), filled.width(), filled.height(), to.width(), to.height()));
  for (size_t i = 0; i < from.size(); ++i)
    if (filled[i]) to[i] = from[i];
}

}  // namespace rrg
