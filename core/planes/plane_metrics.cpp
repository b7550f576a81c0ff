#include "core/planes/plane_metrics.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace rrg {

std::map<int, GtPlane> read_gt_planes(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot open ground-truth planes " + file.string());
  std::map<int, GtPlane> out;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    for (const auto& p : j.at("planes")) {
      GtPlane g;
      g.id = p.at("id").get<int>();
      g.name = p.value("name", "");
      g.category = p.value("category", "");
      const auto n = p.at("normal").get<std::vector<float>>();
      if (n.size() != 3) throw std::runtime_error("plane " + std::to_string(g.id) + ": normal needs 3 numbers");
      g.plane = {Eigen::Vector3f(n[0], n[1], n[2]).normalized(), p.at("offset").get<float>()};
      g.reflective = p.value("reflective", false);
      out[g.id] = g;
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("bad ground-truth planes " + file.string() + ": " + e.what());
  }
  return out;
}

void SegmentationCounts::add(const SegmentationCounts& o) {
  gt += o.gt;
  gt_matched += o.gt_matched;
  detected += o.detected;
  detected_matched += o.detected_matched;
  gt_matched_iou += o.gt_matched_iou;
  detected_matched_iou += o.detected_matched_iou;
  missed_gt.insert(missed_gt.end(), o.missed_gt.begin(), o.missed_gt.end());
  unmatched_detected.insert(unmatched_detected.end(), o.unmatched_detected.begin(), o.unmatched_detected.end());
}

namespace {
int root_of(std::map<int, int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}
}  // namespace

std::map<int, int> group_coplanar_touching(const LabelImage& gt, const std::map<int, GtPlane>& gt_planes,
                                           float max_angle_deg, float max_offset) {
  std::map<int, int> parent;
  for (size_t i = 0; i < gt.size(); ++i)
    if (gt[i]) parent.emplace(gt[i], gt[i]);
  const float cos_max = std::cos(max_angle_deg * std::numbers::pi_v<float> / 180.0f);
  std::set<std::pair<int, int>> tested;
  auto consider = [&](int a, int b) {
    if (a == 0 || b == 0 || a == b || !tested.insert({std::min(a, b), std::max(a, b)}).second) return;
    const auto pa = gt_planes.find(a), pb = gt_planes.find(b);
    if (pa == gt_planes.end() || pb == gt_planes.end()) return;
    const Plane& x = pa->second.plane;
    const Plane& y = pb->second.plane;
    if (x.n.dot(y.n) >= cos_max && std::abs(x.d - y.d) <= max_offset) parent[root_of(parent, a)] = root_of(parent, b);
  };
  for (int v = 0; v < gt.height(); ++v)
    for (int u = 0; u < gt.width(); ++u) {
      if (u + 1 < gt.width()) consider(gt(u, v), gt(u + 1, v));
      if (v + 1 < gt.height()) consider(gt(u, v), gt(u, v + 1));
    }
  std::map<int, int> out;
  for (auto& [id, p] : parent) out[id] = root_of(parent, id);
  return out;
}

SegmentationCounts score_segmentation(const LabelImage& detected, const LabelImage& gt,
                                      const std::map<int, GtPlane>& gt_planes, double min_fraction, double min_iou) {
  if (!detected.same_size(gt)) throw std::invalid_argument("score_segmentation: detected and GT maps differ in size");
  const std::map<int, int> group = group_coplanar_touching(gt, gt_planes);
  std::map<int, int64_t> gt_area, det_area;
  std::map<std::pair<int, int>, int64_t> inter;
  for (size_t i = 0; i < gt.size(); ++i) {
    const int g = gt[i] ? group.at(gt[i]) : 0, d = detected[i];
    if (g) ++gt_area[g];
    if (d) ++det_area[d];
    if (g && d) ++inter[{g, d}];
  }
  const double min_pixels = min_fraction * double(gt.size());
  SegmentationCounts c;
  // Strict: one-to-one by IoU > min_iou.
  std::set<int> iou_gt, iou_det;
  for (const auto& [key, n] : inter) {
    const auto [g, d] = key;
    const double iou = double(n) / double(gt_area[g] + det_area[d] - n);
    if (iou > min_iou) iou_gt.insert(g), iou_det.insert(d);
  }
  // Documented rule: each detection belongs to its majority GT region.
  std::map<int, std::pair<int, int64_t>> owner;  // detection -> (GT region, pixels in it)
  for (const auto& [key, n] : inter) {
    auto& o = owner[key.second];
    if (n > o.second) o = {key.first, n};
  }
  std::set<int> good_det;
  std::map<int, int64_t> covered;  // GT region -> pixels of its correct detections inside it
  for (const auto& [d, o] : owner)
    if (2 * o.second > det_area[d]) {
      good_det.insert(d);
      covered[o.first] += o.second;
    }
  for (const auto& [g, n] : gt_area)
    if (double(n) > min_pixels) {
      ++c.gt;
      const bool found = 2 * covered[g] > n;
      c.gt_matched += found ? 1 : 0;
      c.gt_matched_iou += iou_gt.count(g);
      if (!found) c.missed_gt.push_back(g);
    }
  for (const auto& [d, n] : det_area)
    if (double(n) > min_pixels) {
      ++c.detected;
      c.detected_matched += good_det.count(d);
      c.detected_matched_iou += iou_det.count(d);
      if (!good_det.count(d)) c.unmatched_detected.push_back(d);
    }
  return c;
}

void IdentificationScorer::add(const LabelImage& gt, const Image<int32_t>& global_map) {
  if (!gt.same_size(global_map)) throw std::invalid_argument("IdentificationScorer: GT and global maps differ in size");
  std::map<int, std::map<int, int64_t>> counts;  // GT id -> global id -> pixels (0 = unlabelled)
  std::map<int, int64_t> area;
  for (size_t i = 0; i < gt.size(); ++i) {
    if (!gt[i]) continue;
    ++area[gt[i]];
    ++counts[gt[i]][global_map[i]];
    if (global_map[i]) ++pixels_[{global_map[i], gt[i]}];
  }
  std::map<int, int> ids;
  for (const auto& [g, n] : area) {
    if (double(n) <= min_fraction_ * double(gt.size())) continue;
    ++seen_frames_[g];
    int best = 0;
    int64_t best_n = 0, labelled = 0;
    for (const auto& [id, k] : counts[g])
      if (id) {
        labelled += k;
        if (k > best_n) best = id, best_n = k;
      }
    if (2 * labelled >= n) ids[g] = best;
  }
  frame_ids_.push_back(std::move(ids));
}

namespace {

// The id a remap table gives `id` (ids beyond the table map to themselves).
int canonical_id(const std::vector<int32_t>& remap, int id) {
  return id >= 0 && size_t(id) < remap.size() ? int(remap[size_t(id)]) : id;
}

// The key with the largest count.
int majority_key(const std::map<int, int64_t>& counts) {
  return std::max_element(counts.begin(), counts.end(), [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

}  // namespace

std::map<int, std::map<int, int64_t>> IdentificationScorer::pixels_by_global(const std::vector<int32_t>& remap) const {
  std::map<int, std::map<int, int64_t>> out;
  for (const auto& [key, n] : pixels_) out[canonical_id(remap, key.first)][key.second] += n;
  return out;
}

IdStability IdentificationScorer::id_stability(const std::vector<int32_t>& remap) const {
  std::map<int, std::map<int, int>> hist;  // GT id -> canonical id -> frames
  for (const auto& f : frame_ids_)
    for (const auto& [g, id] : f) ++hist[g][canonical_id(remap, id)];
  IdStability s;
  for (const auto& [g, h] : hist) {
    int total = 0, mode = 0;
    for (const auto& [id, n] : h) total += n, mode = std::max(mode, n);
    ++s.planes;
    s.frames += total;
    s.consistent += mode;
    if (double(mode) >= 0.95 * double(total))
      ++s.stable;
    else
      s.unstable[g] = h;
  }
  const auto by_global = pixels_by_global(remap);
  for (const auto& [g, h] : hist) {
    if (s.unstable.contains(g)) continue;
    const int modal = std::max_element(h.begin(), h.end(), [](const auto& a, const auto& b) { return a.second < b.second; })->first;
    if (const auto it = by_global.find(modal); it != by_global.end())
      if (const int owner = majority_key(it->second); owner != g) s.on_other_id[g] = {modal, owner};
  }
  for (const auto& [g, h] : s.unstable)
    for (const auto& [id, n] : h)
      if (const auto it = by_global.find(id); it != by_global.end()) s.majority_gt[id] = majority_key(it->second);
  return s;
}

ReflectiveScores IdentificationScorer::reflective(const std::vector<int32_t>& remap, const std::set<int>& accepted,
                                                  const std::map<int, GtPlane>& gt_planes, int min_frames) const {
  auto canon = [&](int id) { return canonical_id(remap, id); };
  const auto by_global = pixels_by_global(remap);  // canonical global -> GT -> px
  std::map<int, std::map<int, int64_t>> by_gt;     // and reverse
  for (const auto& [c, gts] : by_global)
    for (const auto& [g, n] : gts) by_gt[g][c] += n;
  ReflectiveScores s;
  for (int id : accepted) {
    const int c = canon(id);
    ++s.accepted;
    const auto it = by_global.find(c);
    if (it == by_global.end()) continue;
    const int g = majority_key(it->second);
    const auto gp = gt_planes.find(g);
    const bool ok = gp != gt_planes.end() && gp->second.reflective;
    s.accepted_correct += ok ? 1 : 0;
    s.accepted_names.push_back((gp != gt_planes.end() ? gp->second.name : std::to_string(g)) + (ok ? "" : " (not reflective)"));
  }
  std::set<int> accepted_canon;
  for (int id : accepted) accepted_canon.insert(canon(id));
  for (const auto& [g, frames] : seen_frames_) {
    const auto gp = gt_planes.find(g);
    if (gp == gt_planes.end() || !gp->second.reflective || frames < min_frames) continue;
    ++s.gt_reflective;
    const auto it = by_gt.find(g);
    const bool found = it != by_gt.end() && accepted_canon.count(majority_key(it->second)) > 0;
    s.gt_found += found ? 1 : 0;
    s.counted[g] = found;
    if (!found) s.missed_names.push_back(gp->second.name);
  }
  return s;
}

}  // namespace rrg
