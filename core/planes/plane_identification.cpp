#include "core/planes/plane_identification.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace rrg {

namespace {

// Pixels at least `border_m` (on the image at their depth) plus `border_px` pixels inside their
// region of `map`: every pixel of the square of radius r = ceil(border_m · fx / z) + border_px
// around them carries the same non-zero value. O(pixels): a two-pass chessboard distance transform
// gives each pixel the distance k to the nearest pixel of its region that touches another value
// (8-neighbourhood) or the image border; the square of radius r is then uniform exactly when k >= r.
template <class T>
MaskImage interior(const Image<T>& map, const DepthImage& depth, const Intrinsics& K, float border_m, int border_px) {
  const int w = map.width(), h = map.height();
  Image<int32_t> k(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
      for (int dy = -1; !edge && dy <= 1; ++dy)
        for (int dx = -1; !edge && dx <= 1; ++dx) edge = map(x + dx, y + dy) != map(x, y);
      k(x, y) = edge ? 0 : w + h;
    }
  for (int y = 1; y < h; ++y)  // forward: left, upper-left, up, upper-right
    for (int x = 1; x < w; ++x) {
      int d = std::min(k(x - 1, y), std::min(k(x - 1, y - 1), k(x, y - 1)));
      if (x + 1 < w) d = std::min(d, k(x + 1, y - 1));
      k(x, y) = std::min(k(x, y), d + 1);
    }
  for (int y = h - 2; y >= 0; --y)  // backward: right, lower-right, down, lower-left
    for (int x = w - 2; x >= 0; --x) {
      int d = std::min(k(x + 1, y), std::min(k(x + 1, y + 1), k(x, y + 1)));
      if (x > 0) d = std::min(d, k(x - 1, y + 1));
      k(x, y) = std::min(k(x, y), d + 1);
    }
  MaskImage inner(w, h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float z = depth(x, y);
      if (map(x, y) == T(0) || !(z > 0)) continue;
      const int r = std::min(16, (border_m > 0 ? int(std::ceil(border_m * K.fx / z)) : 0) + border_px);
      inner(x, y) = k(x, y) >= r ? 1 : 0;
    }
  return inner;
}

// `map` with the pixels on a colour edge set to 0: a 4-neighbour in the same region whose
// intensity x = (r + g + b) / 3 differs by more than `step`.
Image<int32_t> without_color_edges(const Image<int32_t>& map, const ColorImage& color, float step) {
  const int w = map.width(), h = map.height();
  Image<int32_t> out = map;
  auto x_of = [&](int u, int v) { return color(u, v).sum() / 3.0f; };
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const int id = map(u, v);
      if (id == 0) continue;
      const float x = x_of(u, v);
      for (const auto [du, dv] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const int u2 = u + du, v2 = v + dv;
        if (u2 < w && v2 < h && map(u2, v2) == id && std::abs(x_of(u2, v2) - x) > step) out(u, v) = out(u2, v2) = 0;
      }
    }
  return out;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

ReflectiveFillParams IdentificationParams::fill_params() const {
  ReflectiveFillParams f = fill;
  f.noise = segmentation.noise;
  // One surface for the fill (the mask's own depth against its ring's plane) is one for the table.
  f.same_surface_angle_deg = table.max_normal_angle_deg;
  f.same_surface_distance = table.max_distance;
  return f;
}

RegionMatch IdentificationParams::region_match() const {
  return {table.max_normal_angle_deg, table.max_distance, table.min_overlap};
}

void IdentificationParams::validate() const {
  segmentation.validate();
  fill_params().validate();
  table.validate();
  vote.validate();
  if (!(variance_threshold >= 0)) throw std::invalid_argument("IdentificationParams: variance_threshold must be >= 0");
  if (!(area_threshold >= 0 && area_threshold < 1))
    throw std::invalid_argument("IdentificationParams: area_threshold must be in [0, 1)");
  if (!(variance_border_voxels >= 0 && variance_border_voxels <= 64))
    throw std::invalid_argument("IdentificationParams: variance_border_voxels must be in [0, 64]");
  if (!(variance_border_pixels >= 0 && variance_border_pixels <= 16))
    throw std::invalid_argument("IdentificationParams: variance_border_pixels must be in [0, 16]");
  if (!(min_mask_overlap >= 0 && min_mask_overlap <= 1))
    throw std::invalid_argument("IdentificationParams: min_mask_overlap must be in [0, 1]");
}

PlaneIdentifier::PlaneIdentifier(const IdentificationParams& params, std::unique_ptr<SemanticCue> cue)
    : params_(params), cue_(std::move(cue)), table_(params.table), vote_(params.vote) {
  params_.validate();
  if (!cue_) throw std::invalid_argument("PlaneIdentifier: no semantic cue");
}

std::vector<SemanticMask> PlaneIdentifier::semantic_masks(const IdentificationFrame& frame) {
  if (!frame.depth || !frame.color) throw std::invalid_argument("PlaneIdentifier::semantic_masks: depth and colour are required");
  std::vector<SemanticMask> masks = cue_->segment({frame.color, frame.labels, frame.index});
  for (const SemanticMask& m : masks)
    if (!m.mask.same_size(*frame.depth))
      throw std::runtime_error("semantic cue " + cue_->name() + ": mask size differs from the frame");
  return masks;
}

IdentificationResult PlaneIdentifier::identify(const IdentificationFrame& frame, const Image<float>& color_variance) {
  if (!frame.depth || !frame.color) throw std::invalid_argument("PlaneIdentifier::identify: depth and colour are required");
  const DepthImage& depth = *frame.depth;
  if (!depth.same_size(*frame.color) || !depth.same_size(color_variance))
    throw std::invalid_argument(fmt::format("PlaneIdentifier::identify: depth {}x{}, colour {}x{} and C_var {}x{} differ",
                                            depth.width(), depth.height(), frame.color->width(), frame.color->height(),
                                            color_variance.width(), color_variance.height()));
  const auto t_start = std::chrono::steady_clock::now();
  IdentificationResult out;

  auto t0 = std::chrono::steady_clock::now();
  out.segmentation = segment_planes(depth, frame.K, params_.segmentation);
  out.timings.segment_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  const auto observations = table_.observe(out.segmentation, depth, frame.K, frame.T_wc);
  out.association = table_.associate(observations, frame.index);
  for (const auto& [kept, gone] : out.association.merges) vote_.merge(kept, gone);
  out.global_map = table_.global_map(out.segmentation.labels, out.association);
  out.remap = table_.remap_table();
  out.timings.associate_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  std::vector<SemanticMask> own;
  if (!frame.masks) own = semantic_masks(frame);
  const std::vector<SemanticMask>& masks = frame.masks ? *frame.masks : own;
  for (const SemanticMask& m : masks)
    if (!m.mask.same_size(depth)) throw std::runtime_error("semantic cue " + cue_->name() + ": mask size differs from the frame");
  // Per global plane: pixels, pixels above δ_v, and overlap (all pixels, pixels above δ_v) with
  // every mask; per mask its pixel count.
  // The variance counts (high_variance, overlap_inner, overlap_high) use the plane's interior
  // pixels only (IdentificationParams::variance_border_voxels).
  struct Stats {
    int64_t pixels = 0, inner = 0, high_variance = 0;
    double variance_sum = 0;
    std::vector<int64_t> overlap, overlap_inner, overlap_high;
  };
  // Interiors: of the planes, and of the reflective masks (a colour edge at a mask's border
  // aliases into C_var the same way a plane border does).
  const float border_m = params_.variance_border_voxels * std::max(frame.voxel_size, 0.0f);
  const int border_px = params_.variance_border_pixels;
  const MaskImage plane_inner =
      params_.variance_skip_color_edges
          ? interior(without_color_edges(out.global_map, *frame.color, 2.0f * std::sqrt(params_.variance_threshold)), depth,
                     frame.K, border_m, border_px)
          : interior(out.global_map, depth, frame.K, border_m, border_px);
  std::vector<MaskImage> mask_inner(masks.size());
  for (size_t m = 0; m < masks.size(); ++m)
    if (masks[m].reflective) mask_inner[m] = interior(masks[m].mask, depth, frame.K, border_m, border_px);
  std::map<int, Stats> stats;
  std::vector<int64_t> mask_pixels(masks.size(), 0);
  for (size_t i = 0; i < out.global_map.size(); ++i) {
    for (size_t m = 0; m < masks.size(); ++m) mask_pixels[m] += masks[m].mask[i] ? 1 : 0;
    const int id = out.global_map[i];
    if (id == 0) continue;
    Stats& s = stats[id];
    if (s.overlap.empty())
      s.overlap.assign(masks.size(), 0), s.overlap_inner.assign(masks.size(), 0), s.overlap_high.assign(masks.size(), 0);
    ++s.pixels;
    s.variance_sum += color_variance[i];
    const bool inner = plane_inner[i] != 0;
    const bool high = inner && color_variance[i] > params_.variance_threshold;
    s.inner += inner ? 1 : 0;
    s.high_variance += high ? 1 : 0;
    for (size_t m = 0; m < masks.size(); ++m)
      if (masks[m].mask[i]) {
        ++s.overlap[m];
        const bool in_mask = inner && (!masks[m].reflective || mask_inner[m][i] != 0);
        s.overlap_inner[m] += in_mask ? 1 : 0;
        s.overlap_high[m] += in_mask && high ? 1 : 0;
      }
  }
  // A plane's mask: a reflective mask that lies mostly on it (>= min_mask_overlap of the mask's
  // pixels: a mirror or a screen on a wall is a part of the wall's plane, and the plane's largest
  // mask is then the wall), else the mask of largest overlap covering >= min_mask_overlap of the
  // plane (its label, for logs).
  std::map<int, int> plane_mask;  // global id -> associated mask index (-1 = none)
  for (auto& [id, s] : stats) {
    int best = -1;
    for (size_t m = 0; m < masks.size(); ++m)
      if (masks[m].reflective && s.overlap[m] > 0 &&
          double(s.overlap[m]) >= params_.min_mask_overlap * double(mask_pixels[m]) &&
          (best < 0 || s.overlap[m] > s.overlap[size_t(best)]))
        best = int(m);
    if (best < 0) {
      for (size_t m = 0; m < masks.size(); ++m)
        if (s.overlap[m] > 0 && (best < 0 || s.overlap[m] > s.overlap[size_t(best)])) best = int(m);
      if (best >= 0 && double(s.overlap[size_t(best)]) < params_.min_mask_overlap * double(s.pixels)) best = -1;
    }
    plane_mask[id] = best;
  }
  out.timings.semantic_ms = ms_since(t0);

  t0 = std::chrono::steady_clock::now();
  const int64_t window = window_++;
  out.reflection_mask = MaskImage(depth.width(), depth.height(), 0);
  std::vector<int> confirmed_masks;
  std::vector<int> confirmed_planes;
  for (const auto& [id, s] : stats) {
    PlaneVerdict v;
    v.global_id = id;
    v.pixels = s.pixels;
    const int m = plane_mask[id];
    if (m >= 0) v.label = masks[size_t(m)].label;
    const bool reflective_mask = m >= 0 && masks[size_t(m)].reflective;
    v.candidate = cue_->every_plane_is_candidate() || reflective_mask;
    // The variance check looks at the region claimed reflective: the plane's interior pixels
    // inside its reflective mask when it has one, else all of its interior pixels.
    const int64_t region = reflective_mask ? s.overlap_inner[size_t(m)] : s.inner;
    const int64_t region_high = reflective_mask ? s.overlap_high[size_t(m)] : s.high_variance;
    v.variance_fraction = region > 0 ? float(double(region_high) / double(region)) : 0.0f;
    v.variance_mean = s.pixels > 0 ? float(s.variance_sum / double(s.pixels)) : 0.0f;
    v.reflective_now = v.candidate && v.variance_fraction > params_.area_threshold;
    v.accepted = vote_.record(id, window, v.reflective_now);
    // The predicted reflection mask of a confirmed plane: its reflective semantic mask; with a cue
    // that makes every plane a candidate (`none`), the plane's own pixels. A confirmed plane on
    // which the cue finds no reflective mask in this frame predicts nothing: its fallback mask is
    // a non-reflective category (a "wall" mask covers every wall in view), never a reflection.
    if (v.accepted) {
      if (cue_->every_plane_is_candidate()) confirmed_planes.push_back(id);
      else if (reflective_mask) confirmed_masks.push_back(m);
    }
    out.planes.push_back(v);
  }
  for (size_t i = 0; i < out.reflection_mask.size(); ++i) {
    bool on = false;
    for (int m : confirmed_masks) on = on || masks[size_t(m)].mask[i] != 0;
    for (int id : confirmed_planes) on = on || out.global_map[i] == id;
    out.reflection_mask[i] = on ? 1 : 0;
  }
  out.timings.verify_ms = ms_since(t0);
  out.timings.total_ms = ms_since(t_start);
  return out;
}

std::set<int> undecided_candidates(const std::set<int>& previous, const IdentificationResult& window,
                                   const ReflectiveVote& vote, const GlobalPlaneTable& table,
                                   bool every_plane_is_candidate) {
  std::set<int> open;
  if (every_plane_is_candidate) return open;
  const ReflectiveVoteParams& vp = vote.params();
  const auto undecided = [&](int id) {
    const int seen_windows = vote.history_size(id);
    return !vote.accepted(id) && seen_windows < vp.windows &&
           vote.reflective_count(id) + (vp.windows - seen_windows) >= vp.min_reflective;
  };
  std::set<int> seen;
  for (const PlaneVerdict& v : window.planes) {
    seen.insert(v.global_id);
    if (v.candidate && undecided(v.global_id)) open.insert(v.global_id);
  }
  for (const int id : previous) {
    const int c = table.canonical(id);
    if (!seen.count(c) && undecided(c)) open.insert(c);
  }
  return open;
}

}  // namespace rrg
