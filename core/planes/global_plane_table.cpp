#include "core/planes/global_plane_table.h"

#include <spdlog/fmt/fmt.h>
#include <spdlog/fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rrg {

namespace {

// Points of one surface as far as the tests below need them: their moments, the plane fitted to
// them, and the segmenter's tolerances at the distance they were seen from.
struct SurfaceSample {
  PlaneMoments moments;
  PlaneFit fit;
  float same_plane_distance = 0.01f;  // LocalPlane::same_plane_distance
  float planar_rms = 0.0f;            // LocalPlane::planar_rms; 0 = no planarity bound

  SurfaceSample(const PlaneMoments& m, float same_plane, float planar)
      : moments(m), fit(fit_plane(m)), same_plane_distance(same_plane), planar_rms(planar) {}
};

PlaneMoments moments_of(std::span<const Eigen::Vector3f> points) {
  PlaneMoments m;
  for (const Eigen::Vector3f& p : points) m.add(p);
  return m;
}

// One local plane of the frame being associated, with the plane fitted to its points.
struct FittedObservation : SurfaceSample {
  const LocalObservation* obs = nullptr;

  explicit FittedObservation(const LocalObservation& o)
      : SurfaceSample(moments_of(o.points), o.same_plane_distance, o.planar_rms), obs(&o) {}
};

// Whether two samples are one surface: one plane explains both point sets as well as their own
// planes do.
//  - Offset: the plane fitted to their union has each sample's centroid within that sample's
//    coplanarity tolerance (same_plane_distance, the segmenter's step 3).
//  - Tilt: the union's RMS residual is within the segmenter's planarity bound (planar_rms, pooled
//    over the points) and within twice the samples' own RMS (pooled; at least the segmenter's
//    distance scale same_plane_distance / 3, so noise-free pieces are not held to zero). Two parallel
//    layers side by side, each with residual σ, tilt the union's plane until both centroids lie on it,
//    and leave a residual variance σ² + δ²/16 (δ the offset): twice σ is exceeded once δ > √48 σ
//    ≈ 7 σ (a chair's seat 6 cm over the floor beside it, σ 5.6 mm: 3.0 times).
// Each sample's own normal is not compared. A small piece's fit tilts by 5–15° at 4–5 m (strips of
// a wall between shelves and posters, whose own RMS the pixels of the things before them raise),
// and over the metres between two pieces that tilt exceeds any noise bound, while the union's fit,
// spanning both, is well determined: such pieces have 1.2–1.9 times their own RMS about it.
bool same_surface(const SurfaceSample& a, const SurfaceSample& b) {
  if (!a.fit.valid || !b.fit.valid) return false;
  PlaneMoments joint = a.moments;
  joint.merge(b.moments);
  const PlaneFit fit = fit_plane(joint);
  if (!fit.valid) return false;
  const double na = double(a.moments.count()), nb = double(b.moments.count());
  const auto pooled = [&](double va, double vb) { return (na * va + nb * vb) / (na + nb); };
  const auto sq = [](float x) { return double(x) * double(x); };
  const bool bounded = a.planar_rms > 0 && b.planar_rms > 0;
  const double noise_bound = pooled(sq(a.planar_rms), sq(b.planar_rms));
  const double own = pooled(std::max(double(a.fit.mse), sq(a.same_plane_distance / 3.0f)),
                            std::max(double(b.fit.mse), sq(b.same_plane_distance / 3.0f)));
  return std::abs(fit.plane.signed_distance(a.fit.centroid)) < a.same_plane_distance &&
         std::abs(fit.plane.signed_distance(b.fit.centroid)) < b.same_plane_distance &&
         (!bounded || double(fit.mse) <= noise_bound) && double(fit.mse) <= 4.0 * own;
}

}  // namespace

void GlobalPlaneParams::validate() const {
  auto need = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("GlobalPlaneParams: ") + what);
  };
  need(max_normal_angle_deg > 0 && max_normal_angle_deg < 90, "max_normal_angle_deg must be in (0, 90)");
  need(max_distance > 0, "max_distance must be > 0");
  need(cell_size > 0, "cell_size must be > 0");
  need(min_overlap >= 0 && min_overlap < 1, "min_overlap must be in [0, 1)");
  need(min_iou >= 0 && min_iou < 1, "min_iou must be in [0, 1)");
  need(max_gap >= 0, "max_gap must be >= 0");
  need(recent_frames >= 0, "recent_frames must be >= 0");
  need(merge_min_overlap > 0 && merge_min_overlap <= 1, "merge_min_overlap must be in (0, 1]");
  need(point_stride >= 1, "point_stride must be >= 1");
}

std::string GlobalPlaneParams::to_string() const {
  return fmt::format("normal <= {} deg, distance <= {} m, grid {} m, overlap > {}, IoU > {}, gap < {} m "
                     "(seen within {} frames), merge overlap > {}",
                     max_normal_angle_deg, max_distance, cell_size, min_overlap, min_iou, max_gap,
                     recent_frames, merge_min_overlap);
}

GlobalPlaneTable::GlobalPlaneTable(const GlobalPlaneParams& params) : params_(params), parent_{0} {
  params_.validate();
}

std::vector<LocalObservation> GlobalPlaneTable::observe(const PlaneSegmentation& seg, const DepthImage& depth,
                                                        const Intrinsics& K, const Eigen::Isometry3f& T_wc) const {
  if (!seg.labels.same_size(depth) || depth.width() != K.width || depth.height() != K.height)
    throw std::invalid_argument("GlobalPlaneTable::observe: labels, depth and intrinsics differ in size");
  std::vector<LocalObservation> out(seg.planes.size());
  for (size_t i = 0; i < seg.planes.size(); ++i) {
    out[i].local_id = seg.planes[i].id;
    out[i].plane = seg.planes[i].plane.transformed(T_wc);
    out[i].centroid = T_wc * seg.planes[i].centroid;
    out[i].same_plane_distance = seg.planes[i].same_plane_distance;
    out[i].planar_rms = seg.planes[i].planar_rms;
    out[i].points.reserve(size_t(seg.planes[i].pixels / (params_.point_stride * params_.point_stride) + 16));
  }
  const int s = params_.point_stride;
  for (int v = 0; v < depth.height(); v += s)
    for (int u = 0; u < depth.width(); u += s) {
      const int id = seg.labels(u, v);
      if (id == 0 || id > int(out.size())) continue;
      out[size_t(id - 1)].points.push_back(T_wc * K.unproject(float(u), float(v), depth(u, v)));
    }
  return out;
}

float GlobalPlaneTable::cos_max_normal_angle() const {
  return std::cos(params_.max_normal_angle_deg * std::numbers::pi_v<float> / 180.0f);
}

bool GlobalPlaneTable::geometric_match(const Plane& a, const Eigen::Vector3f& centroid_b) const {
  // Only plane a's normal is compared here; callers pass both orders where symmetry matters.
  return std::abs(a.signed_distance(centroid_b)) <= params_.max_distance;
}

std::vector<CandidateScore> GlobalPlaneTable::score(const LocalObservation& obs, int64_t frame) const {
  const float cos_max = cos_max_normal_angle();
  std::vector<CandidateScore> out;
  for (const GlobalPlane& g : planes_) {
    if (!g.alive || g.plane.n.dot(obs.plane.n) < cos_max || !geometric_match(g.plane, obs.centroid)) continue;
    Footprint local(g.footprint.basis(), params_.cell_size);
    local.add_points(obs.points);
    CandidateScore s;
    s.global_id = g.id;
    s.overlap = g.footprint.overlap_ratio(local);
    s.iou = box_iou(g.footprint.box(), local.box());
    s.gap = box_gap(g.footprint.box(), local.box());
    s.recent = frame - g.last_seen <= params_.recent_frames;
    s.matched = s.overlap > params_.min_overlap || s.iou > params_.min_iou || (s.recent && s.gap < params_.max_gap);
    out.push_back(s);
  }
  return out;
}

void GlobalPlaneTable::absorb(GlobalPlane& g, const LocalObservation& obs, const PlaneMoments& moments,
                              int64_t frame) {
  g.moments.merge(moments);
  const PlaneFit fit = fit_plane(g.moments);
  if (fit.valid) {
    g.plane = fit.plane;
    if (g.plane.n.dot(obs.plane.n) < 0) g.plane = {-g.plane.n, -g.plane.d};  // keep the observed side
    g.centroid = fit.centroid;
  }
  g.footprint.add_points(obs.points);
  g.last_seen = std::max(g.last_seen, frame);
  ++g.observations;
  g.same_plane_distance = g.observations == 1 ? obs.same_plane_distance
                                              : std::min(g.same_plane_distance, obs.same_plane_distance);
}

int GlobalPlaneTable::create(const LocalObservation& obs, const PlaneMoments& moments, int64_t frame) {
  GlobalPlane g;
  g.id = int(planes_.size()) + 1;
  g.plane = obs.plane;
  g.centroid = obs.centroid;
  g.footprint = Footprint(PlaneBasis::from_plane(obs.plane, obs.centroid), params_.cell_size);
  g.first_seen = g.last_seen = frame;
  planes_.push_back(std::move(g));
  parent_.push_back(planes_.back().id);
  absorb(planes_.back(), obs, moments, frame);
  planes_.back().plane.n = planes_.back().plane.n.normalized();
  return planes_.back().id;
}

FrameAssociation GlobalPlaneTable::associate(std::span<const LocalObservation> observations, int64_t frame) {
  FrameAssociation out;
  int max_local = 0;
  for (const auto& o : observations) max_local = std::max(max_local, o.local_id);
  out.local_to_global.assign(size_t(max_local) + 1, 0);
  std::vector<int> touched;
  std::vector<std::pair<int, const FittedObservation*>> claims;  // (instance, a local plane of this frame in it)
  std::vector<std::pair<int, int>> bridged_twice;                // instances to merge after the frame
  // A local plane that took instance `took` also matched instance `other`: whether it is one surface
  // with `other` (its accumulated points, held to its closest look's tolerance), and if so whether an
  // earlier frame recorded the same (then true: merge them); otherwise this frame is recorded.
  const auto bridges = [&](int took, int other, const SurfaceSample& piece) {
    GlobalPlane& a = planes_[size_t(canonical(took) - 1)];
    const GlobalPlane& b = planes_[size_t(canonical(other) - 1)];
    if (!same_surface(piece, SurfaceSample(b.moments, b.same_plane_distance, 0.0f))) return false;
    const auto earlier = [&](const GlobalPlane& g, int to) {
      return std::any_of(g.bridged.begin(), g.bridged.end(),
                         [&](const auto& e) { return canonical(e.first) == to && e.second < frame; });
    };
    if (earlier(a, b.id) || earlier(b, a.id)) return true;
    if (std::none_of(a.bridged.begin(), a.bridged.end(), [&](const auto& e) { return canonical(e.first) == b.id; }))
      a.bridged.emplace_back(b.id, frame);
    return false;
  };
  std::vector<FittedObservation> fitted;
  fitted.reserve(observations.size());
  for (const LocalObservation& obs : observations) fitted.emplace_back(obs);
  // An instance already holding a local plane of this frame that is a different surface.
  const auto taken = [&](int id, const FittedObservation& f) {
    for (const auto& [g, other] : claims)
      if (g == id && !same_surface(*other, f)) return true;
    return false;
  };
  for (const FittedObservation& f : fitted) {
    const LocalObservation& obs = *f.obs;
    if (obs.points.size() < 3) continue;
    const std::vector<CandidateScore> scores = score(obs, frame);
    // Candidates the observation lies on within its noise come before those only within the
    // filter's 0.1 m (a wall's piece beside a mirror frame's bar 5 cm in front of it); then the
    // highest overlap, IoU, smallest gap.
    const auto on_plane = [&](const CandidateScore& c) {
      return std::abs(planes_[size_t(c.global_id - 1)].plane.signed_distance(obs.centroid)) < obs.same_plane_distance;
    };
    const auto better = [&](const CandidateScore& s, const CandidateScore& b) {
      if (on_plane(s) != on_plane(b)) return on_plane(s);
      if (s.overlap != b.overlap) return s.overlap > b.overlap;
      if (s.iou != b.iou) return s.iou > b.iou;
      return s.gap < b.gap;
    };
    const CandidateScore* best = nullptr;
    std::vector<int> blocked;  // matching instances held by a different surface of this frame
    for (const CandidateScore& s : scores) {
      if (!s.matched) continue;
      if (taken(s.global_id, f)) {
        blocked.push_back(s.global_id);
        continue;
      }
      if (!best || better(s, *best)) best = &s;
    }
    int id = best ? best->global_id : 0;
    // Kept off an instance by a different surface and matching no other: a piece of a surface of
    // this frame (the same surface by the segmenter's test) that was kept off it too joins that piece.
    if (!best && !blocked.empty())
      for (const auto& [g, other] : claims)
        if (same_surface(*other, f) &&
            std::any_of(blocked.begin(), blocked.end(), [&](int b) { return seen_apart(g, b); })) {
          id = g;
          break;
        }
    const bool created = id == 0;
    if (created) {
      id = create(obs, f.moments, frame);
      ++out.created;
    } else {
      absorb(planes_[size_t(id - 1)], obs, f.moments, frame);
    }
    out.local_to_global[size_t(obs.local_id)] = id;
    if (std::find(touched.begin(), touched.end(), id) == touched.end()) touched.push_back(id);
    if (!blocked.empty())
      spdlog::debug("planes: frame {}: local plane {} ({} points) is another surface than instance(s) {} hold here; {} {}",
                    frame, obs.local_id, obs.points.size(), fmt::join(blocked, ","), created ? "created" : "took", id);
    // Seen apart: the instances this plane matched but could not take, and the one it got.
    for (int g : blocked)
      if (g != id && !seen_apart(g, id)) {
        planes_[size_t(g - 1)].apart.push_back(id);
        planes_[size_t(id - 1)].apart.push_back(g);
      }
    claims.emplace_back(id, &f);
    if (!created)
      for (const CandidateScore& s : scores)
        if (s.matched && canonical(s.global_id) != canonical(id) && !taken(s.global_id, f) &&
            !seen_apart(id, s.global_id) && bridges(id, s.global_id, f))
          bridged_twice.emplace_back(id, s.global_id);
  }
  // Two frames in which a piece of one instance was one surface with another: one surface.
  for (const auto& [a, b] : bridged_twice) {
    const int ra = canonical(a), rb = canonical(b);
    if (ra == rb || seen_apart(ra, rb)) continue;
    merge(ra, rb);
    out.merges.emplace_back(std::min(ra, rb), std::max(ra, rb));
    spdlog::debug("planes: frame {}: instances {} and {} were bridged by one surface in two frames; merged", frame, ra, rb);
  }
  for (int& t : touched) t = canonical(t);
  merge_pass(touched, out);
  for (int& id : out.local_to_global) id = id > 0 ? canonical(id) : 0;
  return out;
}

void GlobalPlaneTable::merge_pass(std::span<const int> touched, FrameAssociation& out) {
  const float cos_max = cos_max_normal_angle();
  for (int t : touched) {
    for (bool changed = true; changed;) {
      changed = false;
      const int a = canonical(t);
      for (const GlobalPlane& other : planes_) {
        const GlobalPlane& ga = planes_[size_t(a - 1)];
        if (!other.alive || other.id == a || ga.plane.n.dot(other.plane.n) < cos_max) continue;
        if (!geometric_match(ga.plane, other.centroid) || !geometric_match(other.plane, ga.centroid)) continue;
        if (seen_apart(a, other.id)) continue;
        // Both footprints in a's basis; the smaller one's cells inside the larger one, dilated.
        Footprint b_in_a(ga.footprint.basis(), params_.cell_size);
        b_in_a.merge(other.footprint);
        const float ratio = ga.footprint.cells() >= b_in_a.cells() ? ga.footprint.overlap_ratio(b_in_a)
                                                                    : b_in_a.overlap_ratio(ga.footprint);
        if (ratio <= params_.merge_min_overlap) continue;
        const int kept = std::min(a, other.id), gone = std::max(a, other.id);
        merge(kept, gone);
        out.merges.emplace_back(kept, gone);
        changed = true;
        break;
      }
    }
  }
}

bool GlobalPlaneTable::merge(int a, int b) {
  const int ra = canonical(a), rb = canonical(b);
  if (ra == rb || ra <= 0 || rb <= 0 || ra > int(planes_.size()) || rb > int(planes_.size())) return false;
  const int kept = std::min(ra, rb), gone = std::max(ra, rb);
  GlobalPlane& k = planes_[size_t(kept - 1)];
  GlobalPlane& g = planes_[size_t(gone - 1)];
  const Eigen::Vector3f side = k.plane.n;
  k.moments.merge(g.moments);
  const PlaneFit fit = fit_plane(k.moments);
  if (fit.valid) {
    k.plane = fit.plane;
    if (k.plane.n.dot(side) < 0) k.plane = {-k.plane.n, -k.plane.d};
    k.centroid = fit.centroid;
  }
  k.footprint.merge(g.footprint);
  k.first_seen = std::min(k.first_seen, g.first_seen);
  k.last_seen = std::max(k.last_seen, g.last_seen);
  k.observations += g.observations;
  k.same_plane_distance = std::min(k.same_plane_distance, g.same_plane_distance);
  k.apart.insert(k.apart.end(), g.apart.begin(), g.apart.end());
  g.apart.clear();
  k.bridged.insert(k.bridged.end(), g.bridged.begin(), g.bridged.end());
  g.bridged.clear();
  g.alive = false;
  parent_[size_t(gone)] = kept;
  return true;
}

bool GlobalPlaneTable::seen_apart(int a, int b) const {
  const GlobalPlane* ga = find(a);
  const int rb = canonical(b);
  if (!ga || ga->id == rb) return false;
  return std::any_of(ga->apart.begin(), ga->apart.end(), [&](int x) { return canonical(x) == rb; });
}

int GlobalPlaneTable::canonical(int id) const {
  if (id <= 0 || id >= int(parent_.size())) return id;
  int r = id;
  while (parent_[size_t(r)] != r) r = parent_[size_t(r)];
  while (parent_[size_t(id)] != r) {  // path compression
    const int next = parent_[size_t(id)];
    parent_[size_t(id)] = r;
    id = next;
  }
  return r;
}

std::vector<int32_t> GlobalPlaneTable::remap_table() const {
  std::vector<int32_t> table(parent_.size());
  for (size_t i = 0; i < table.size(); ++i) table[i] = canonical(int(i));
  return table;
}

Image<int32_t> GlobalPlaneTable::global_map(const LabelImage& local_labels, const FrameAssociation& assoc) const {
  Image<int32_t> out(local_labels.width(), local_labels.height(), 0);
  for (size_t i = 0; i < local_labels.size(); ++i) {
    const size_t l = local_labels[i];
    if (l > 0 && l < assoc.local_to_global.size()) out[i] = canonical(assoc.local_to_global[l]);
  }
  return out;
}

const GlobalPlane* GlobalPlaneTable::find(int id) const {
  const int r = canonical(id);
  return r >= 1 && r <= int(planes_.size()) ? &planes_[size_t(r - 1)] : nullptr;
}

std::vector<int> GlobalPlaneTable::live_ids() const {
  std::vector<int> ids;
  for (const GlobalPlane& g : planes_)
    if (g.alive) ids.push_back(g.id);
  return ids;
}

}  // namespace rrg
