#include "core/planes/observed_variance.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace rrg {

ObservedVariance::ObservedVariance(const Intrinsics& K, float depth_tolerance, int stride)
    : K_(K), tolerance_(depth_tolerance), stride_(stride) {
  if (stride < 1) throw std::invalid_argument("ObservedVariance: stride must be >= 1, got " + std::to_string(stride));
  if (!(depth_tolerance > 0))
    throw std::invalid_argument("ObservedVariance: depth tolerance must be > 0, got " + std::to_string(depth_tolerance));
}

void ObservedVariance::add(const Eigen::Isometry3f& T_wc, const DepthImage& depth, const ColorImage& color,
                           const LabelImage& planes) {
  const auto check = [&](int w, int h, const char* what) {
    if (w != K_.width || h != K_.height)
      throw std::invalid_argument(std::string("ObservedVariance::add: the ") + what + " is " + std::to_string(w) + "x" +
                                  std::to_string(h) + ", the camera " + K_.to_string());
  };
  check(depth.width(), depth.height(), "depth");
  check(color.width(), color.height(), "colour image");
  check(planes.width(), planes.height(), "plane map");
  views_.push_back(View{T_wc.inverse(), T_wc, depth, color, planes});
}

std::map<int, PlaneObservedVariance> ObservedVariance::stats(const std::set<int>& planes, float delta_v) const {
  std::map<int, std::vector<float>> variances;
  std::map<int, double> rgb_sums;  // per plane, the sum over points of the mean of the channels' variances
  for (const View& src : views_)
    for (int y = 0; y < K_.height; y += stride_)
      for (int x = 0; x < K_.width; x += stride_) {
        const int id = src.planes(x, y);
        const float z = src.depth(x, y);
        if (id == 0 || !planes.count(id) || !(z > 0)) continue;
        const Eigen::Vector3f X = src.T_wc * K_.unproject(float(x), float(y), z);
        double mean = 0, m2 = 0;  // Welford over the point's observations of x = (r + g + b) / 3
        Eigen::Vector3d mean_c = Eigen::Vector3d::Zero(), m2_c = Eigen::Vector3d::Zero();  // and of r, g, b
        int n = 0;
        for (const View& v : views_) {
          const Eigen::Vector3f p = v.T_cw * X;
          if (!(p.z() > 0)) continue;
          const Eigen::Vector2f uv = K_.project(p);
          const float uf = uv.x() + 0.5f, vf = uv.y() + 0.5f;  // nearest pixel, as fusion reads it
          if (!(uf >= 0 && vf >= 0 && uf < float(K_.width) && vf < float(K_.height))) continue;
          const int u = int(uf), w = int(vf);
          if (v.planes(u, w) != id || !(std::abs(v.depth(u, w) - p.z()) <= tolerance_)) continue;
          const Eigen::Vector3d c = v.color(u, w).cast<double>();
          const double xi = c.sum() / 3.0, delta = xi - mean;
          ++n;
          mean += delta / n;
          m2 += delta * (xi - mean);
          const Eigen::Vector3d delta_c = c - mean_c;
          mean_c += delta_c / n;
          m2_c += delta_c.cwiseProduct(c - mean_c);
        }
        if (n >= 2) {
          variances[id].push_back(float(m2 / n));
          rgb_sums[id] += m2_c.sum() / (3.0 * n);
        }
      }
  std::map<int, PlaneObservedVariance> out;
  for (auto& [id, vs] : variances) {
    PlaneObservedVariance s;
    s.points = int64_t(vs.size());
    s.fraction_above = double(std::count_if(vs.begin(), vs.end(), [&](float x) { return x > delta_v; })) / double(vs.size());
    s.mean = std::accumulate(vs.begin(), vs.end(), 0.0) / double(vs.size());
    s.mean_rgb = rgb_sums[id] / double(vs.size());
    std::nth_element(vs.begin(), vs.begin() + std::ptrdiff_t(vs.size() / 2), vs.end());
    s.median = vs[vs.size() / 2];
    out[id] = s;
  }
  return out;
}

}  // namespace rrg
