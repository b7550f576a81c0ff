#include "core/slam/reflection_stereo.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace rrg {

namespace {

struct OtherView {
  Eigen::Isometry3f T_cw;
  const ColorImage* C;
  const Image<int32_t>* I;
};

// Bilinear colour at (u, v); the caller keeps (u, v) inside [0, w − 1) x [0, h − 1).
Color bilinear(const ColorImage& im, float u, float v) {
  const int x = int(u), y = int(v);
  const float a = u - float(x), b = v - float(y);
  return (1 - b) * ((1 - a) * im(x, y) + a * im(x + 1, y)) + b * ((1 - a) * im(x, y + 1) + a * im(x + 1, y + 1));
}

}  // namespace

void ReflectionStereoParams::validate() const {
  auto check = [](bool ok, const char* name, double v) {
    if (!ok) throw std::invalid_argument(std::string("ReflectionStereoParams: bad ") + name + " = " + std::to_string(v));
  };
  check(near >= 0, "near", near);
  check(far > near, "far", far);
  check(min_hypotheses >= 2, "min_hypotheses", min_hypotheses);
  check(max_hypotheses >= min_hypotheses, "max_hypotheses", max_hypotheses);
  check(max_views >= 1, "max_views", max_views);
  check(min_baseline >= 0, "min_baseline", min_baseline);
  check(patch_radius >= 0 && patch_radius <= 5, "patch_radius", patch_radius);
}

Image<float> reflection_stereo_depth(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const ColorImage& C,
                                     const Image<int32_t>& I, const MaskImage* want,
                                     std::span<const ReflectivePlane> planes, std::span<const StereoView> others,
                                     const ReflectionStereoParams& p) {
  p.validate();
  const auto check_size = [&](const auto* im, const char* name) {
    if (!im || im->width() != K.width || im->height() != K.height)
      throw std::invalid_argument(std::string("reflection_stereo_depth: ") + name +
                                  (im ? " is " + std::to_string(im->width()) + "x" + std::to_string(im->height())
                                      : std::string(" is missing")) +
                                  ", the camera " + K.to_string());
  };
  check_size(&C, "the colour image");
  check_size(&I, "the plane-id map");
  if (want) check_size(want, "the pixel mask");
  const auto by_id = unit_planes_by_id(planes, "reflection_stereo_depth");

  // The nearest other views (by camera centre) with a baseline of at least min_baseline that show
  // one of the planes.
  const Eigen::Vector3f o = T_wc.translation();
  std::vector<std::pair<float, size_t>> by_distance;
  for (size_t i = 0; i < others.size(); ++i) {
    const StereoView& s = others[i];
    check_size(s.C, "another view's colour image");
    check_size(s.I, "another view's plane-id map");
    const float b = (s.T_wc.translation() - o).norm();
    if (!(b >= p.min_baseline)) continue;
    const bool shows = std::any_of(s.I->pixels().begin(), s.I->pixels().end(),
                                   [&](int32_t id) { return id > 0 && by_id.count(id) > 0; });
    if (shows) by_distance.push_back({b, i});
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<OtherView> views;
  for (size_t k = 0; k < by_distance.size() && int(views.size()) < p.max_views; ++k) {
    const StereoView& s = others[by_distance[k].second];
    views.push_back({s.T_wc.inverse(), s.C, s.I});
  }

  Image<float> out(K.width, K.height, 0.0f);
  if (views.empty()) return out;
  const Eigen::Matrix3f R_wc = T_wc.linear();
  const int r = p.patch_radius, W = K.width, H = K.height;
  // A projection is usable when its bilinear patch stays inside the image.
  const float lo = float(r), hi_x = float(W - 1 - r) - 1e-3f, hi_y = float(H - 1 - r) - 1e-3f;

#pragma omp parallel for schedule(dynamic, 4)
  for (int y = 0; y < H; ++y) {
    std::vector<float> cost;
    std::vector<Color> patch(size_t((2 * r + 1) * (2 * r + 1)));
    for (int x = 0; x < W; ++x) {
      if (want && (*want)(x, y) == 0) continue;
      const int32_t id = I(x, y);
      const auto it = id > 0 ? by_id.find(id) : by_id.end();
      if (it == by_id.end()) continue;
      const Eigen::Vector3f n = it->second.head<3>();
      const Eigen::Vector3f ray_c = K.unproject(float(x), float(y), 1.0f);
      const Eigen::Vector3f d = (R_wc * ray_c).normalized();
      const float denom = n.dot(d);
      if (std::abs(denom) < 1e-6f) continue;
      const float t0 = -(n.dot(o) + it->second.w()) / denom;
      if (!(t0 > 0)) continue;
      const float t_min = t0 + p.near, t_max = t0 + p.far;
      // as many hypotheses as the widest view needs for about a pixel per step
      float span_px = 0;
      for (const OtherView& v : views) {
        const Eigen::Vector3f a = v.T_cw * (o + t_min * d), b = v.T_cw * (o + t_max * d);
        if (a.z() <= 0 || b.z() <= 0) {
          span_px = std::numeric_limits<float>::infinity();
          break;
        }
        span_px = std::max(span_px, (K.project(a) - K.project(b)).norm());
      }
      const int D = int(std::clamp(std::ceil(span_px), float(p.min_hypotheses), float(p.max_hypotheses)));
      for (int dy = -r, k = 0; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx, ++k)
          patch[size_t(k)] = C(std::clamp(x + dx, 0, W - 1), std::clamp(y + dy, 0, H - 1));
      cost.assign(size_t(D), std::numeric_limits<float>::infinity());
      const float inv_min = 1.0f / t_min, inv_max = 1.0f / t_max;
      for (int h = 0; h < D; ++h) {
        const float t = 1.0f / (inv_min + (inv_max - inv_min) * float(h) / float(D - 1));
        const Eigen::Vector3f X = o + t * d;
        float sum = 0;
        int seen = 0;
        for (const OtherView& v : views) {
          const Eigen::Vector3f Xc = v.T_cw * X;
          if (!(Xc.z() > 0)) continue;
          const Eigen::Vector2f q = K.project(Xc);
          if (!(q.x() >= lo && q.x() <= hi_x && q.y() >= lo && q.y() <= hi_y)) continue;
          if ((*v.I)(int(std::lround(q.x())), int(std::lround(q.y()))) != id) continue;  // not through the plane
          float c = 0;
          for (int dy = -r, k = 0; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx, ++k)
              c += (patch[size_t(k)] - bilinear(*v.C, q.x() + float(dx), q.y() + float(dy))).cwiseAbs().sum();
          sum += c;
          ++seen;
        }
        if (seen > 0) cost[size_t(h)] = sum / float(seen);
      }
      const auto best = std::min_element(cost.begin(), cost.end());
      if (!std::isfinite(*best)) continue;
      const int h = int(best - cost.begin());
      float hf = float(h);
      if (h > 0 && h + 1 < D && std::isfinite(cost[size_t(h - 1)]) && std::isfinite(cost[size_t(h + 1)])) {
        const float cm = cost[size_t(h - 1)], c0 = *best, cp = cost[size_t(h + 1)];
        const float curv = cm - 2 * c0 + cp;
        if (curv > 0) hf += std::clamp(0.5f * (cm - cp) / curv, -0.5f, 0.5f);
      }
      const float t = 1.0f / (inv_min + (inv_max - inv_min) * hf / float(D - 1));
      out(x, y) = t / ray_c.norm();  // depth along the optical axis
    }
  }
  return out;
}

}  // namespace rrg
