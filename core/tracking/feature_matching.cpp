#include "core/tracking/feature_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace rrg {
namespace {

// Keypoints bucketed into square cells for radius queries.
class KeypointGrid {
 public:
  KeypointGrid(const std::vector<cv::KeyPoint>& kps, int width, int height, float cell)
      : cell_(cell), cols_(std::max(1, int(std::ceil(width / cell)))), rows_(std::max(1, int(std::ceil(height / cell)))),
        cells_(size_t(cols_ * rows_)) {
    for (size_t i = 0; i < kps.size(); ++i) {
      const int cx = std::clamp(int(kps[i].pt.x / cell_), 0, cols_ - 1), cy = std::clamp(int(kps[i].pt.y / cell_), 0, rows_ - 1);
      cells_[size_t(cy * cols_ + cx)].push_back(int(i));
    }
  }
  template <class F>
  void for_each_near(float x, float y, float r, F f) const {
    const int x0 = std::max(0, int((x - r) / cell_)), x1 = std::min(cols_ - 1, int((x + r) / cell_));
    const int y0 = std::max(0, int((y - r) / cell_)), y1 = std::min(rows_ - 1, int((y + r) / cell_));
    for (int cy = y0; cy <= y1; ++cy)
      for (int cx = x0; cx <= x1; ++cx)
        for (int i : cells_[size_t(cy * cols_ + cx)]) f(i);
  }

 private:
  float cell_;
  int cols_, rows_;
  std::vector<std::vector<int>> cells_;
};

float angle_difference(float a_deg, float b_deg) {
  float d = a_deg - b_deg;
  while (d < 0.0f) d += 360.0f;
  while (d >= 360.0f) d -= 360.0f;
  return d;
}

// Applies rotation consistency, then keeps each keypoint's closest map point.
std::vector<FeatureMatch> finalize(std::vector<FeatureMatch> matches, const std::vector<float>& angle_diff, int bins) {
  std::vector<FeatureMatch> kept;
  for (int i : rotation_consistent(angle_diff, bins)) kept.push_back(matches[size_t(i)]);
  std::unordered_map<int, size_t> best;
  std::vector<FeatureMatch> out;
  for (const FeatureMatch& m : kept) {
    auto it = best.find(m.keypoint);
    if (it == best.end()) {
      best[m.keypoint] = out.size();
      out.push_back(m);
    } else if (m.distance < out[it->second].distance) {
      out[it->second] = m;
    }
  }
  return out;
}

}  // namespace

std::vector<int> rotation_consistent(const std::vector<float>& angle_diff_deg, int bins) {
  std::vector<std::vector<int>> hist(size_t(std::max(1, bins)));
  for (size_t i = 0; i < angle_diff_deg.size(); ++i) {
    int b = int(angle_diff_deg[i] / 360.0f * float(hist.size()));
    b = std::clamp(b, 0, int(hist.size()) - 1);
    hist[size_t(b)].push_back(int(i));
  }
  std::vector<size_t> order(hist.size());
  for (size_t b = 0; b < order.size(); ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return hist[a].size() > hist[b].size(); });
  const size_t top = hist[order[0]].size();
  std::vector<int> keep;
  for (size_t k = 0; k < std::min<size_t>(3, order.size()); ++k) {
    const auto& h = hist[order[k]];
    if (h.empty() || double(h.size()) < 0.1 * double(top)) break;
    keep.insert(keep.end(), h.begin(), h.end());
  }
  std::sort(keep.begin(), keep.end());
  return keep;
}

std::vector<FeatureMatch> match_by_projection(const OrbFrame& frame, const std::vector<const Keyframe*>& window,
                                              const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                                              const OrbParams& params) {
  if (frame.keypoints.empty()) return {};
  const float r0 = params.search_radius_px;
  const KeypointGrid grid(frame.keypoints, K.width, K.height, std::max(8.0f, r0));
  const Eigen::Isometry3f T_cw = T_wc.inverse();
  std::vector<FeatureMatch> matches;
  std::vector<float> angles;
  for (const Keyframe* kf : window) {
    for (size_t j = 0; j < kf->points_world.size(); ++j) {
      const Eigen::Vector3f p = T_cw * kf->points_world[j];
      if (!(p.z() > 0.05f)) continue;
      const Eigen::Vector2f uv = K.project(p);
      if (uv.x() < 0 || uv.y() < 0 || uv.x() > K.width - 1 || uv.y() > K.height - 1) continue;
      const uint8_t* d = kf->descriptors.ptr<uint8_t>(int(j));
      const int octave = kf->keypoints[j].octave;
      const float radius = r0 * float(level_scale(params.scale_factor, octave));
      int best = std::numeric_limits<int>::max(), second = best, best_i = -1;
      grid.for_each_near(uv.x(), uv.y(), radius, [&](int i) {
        const cv::KeyPoint& kp = frame.keypoints[size_t(i)];
        if (std::abs(kp.octave - octave) > 1) return;
        if ((Eigen::Vector2f(kp.pt.x, kp.pt.y) - uv).squaredNorm() > radius * radius) return;
        const int h = hamming_distance(d, frame.descriptors.ptr<uint8_t>(i));
        if (h < best) {
          second = best;
          best = h;
          best_i = i;
        } else if (h < second) {
          second = h;
        }
      });
      if (best_i < 0 || best > params.max_hamming) continue;
      if (second != std::numeric_limits<int>::max() && float(best) >= params.ratio * float(second)) continue;
      matches.push_back({best_i, kf->points_world[j], best});
      angles.push_back(angle_difference(kf->keypoints[j].angle, frame.keypoints[size_t(best_i)].angle));
    }
  }
  return finalize(std::move(matches), angles, params.rotation_bins);
}

std::vector<FeatureMatch> match_brute_force(const OrbFrame& frame, const Keyframe& keyframe, const OrbParams& params) {
  std::vector<FeatureMatch> matches;
  std::vector<float> angles;
  for (size_t i = 0; i < frame.keypoints.size(); ++i) {
    if (!(frame.points_cam[i].z() > 0.0f)) continue;
    const uint8_t* d = frame.descriptors.ptr<uint8_t>(int(i));
    int best = std::numeric_limits<int>::max(), second = best, best_j = -1;
    for (int j = 0; j < keyframe.descriptors.rows; ++j) {
      const int h = hamming_distance(d, keyframe.descriptors.ptr<uint8_t>(j));
      if (h < best) {
        second = best;
        best = h;
        best_j = j;
      } else if (h < second) {
        second = h;
      }
    }
    if (best_j < 0 || best > params.max_hamming) continue;
    if (second != std::numeric_limits<int>::max() && float(best) >= params.ratio * float(second)) continue;
    matches.push_back({int(i), keyframe.points_world[size_t(best_j)], best});
    angles.push_back(angle_difference(keyframe.keypoints[size_t(best_j)].angle, frame.keypoints[i].angle));
  }
  return finalize(std::move(matches), angles, params.rotation_bins);
}

}  // namespace rrg

namespace rrg {

std::vector<BaObservation> to_observations(const OrbFrame& frame, const std::vector<FeatureMatch>& matches,
                                           const OrbParams& params) {
  std::vector<BaObservation> obs;
  obs.reserve(matches.size());
  for (const FeatureMatch& m : matches) {
    const cv::KeyPoint& kp = frame.keypoints[size_t(m.keypoint)];
    BaObservation o;
    o.X_w = m.X_w.cast<double>();
    o.uv = {kp.pt.x, kp.pt.y};
    const float z = frame.points_cam[size_t(m.keypoint)].z();
    if (z > 0.0f) o.u_right = double(kp.pt.x) - double(params.baseline_fx) / double(z);
    if (o.u_right < 0.0) o.u_right = -1.0;  // off the virtual right image: monocular
    const double s = level_scale(params.scale_factor, kp.octave);
    o.inv_sigma2 = 1.0 / (s * s);
    obs.push_back(o);
  }
  return obs;
}

}  // namespace rrg
