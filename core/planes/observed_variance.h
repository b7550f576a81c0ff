#pragma once
// How much temporal colour variance the input itself shows on each ground-truth plane: the
// evaluation's oracle for the variance check of reflective identification (paper §4.1.3, δ_v).
// The check can only accept a reflective plane whose points change intensity across the
// identification frames by more than δ_v on more than δ_area of the plane; when the input does not
// show that (a dim or blurred reflection), no TSDF, however fine, can. This measures it from the
// frames alone, with ground-truth poses, depth and plane maps and no TSDF:
//   - points: every `stride`-th pixel (both axes) of the plane in every added view, back-projected;
//   - a point's observations: its nearest pixel in each view (the one TSDF fusion would read) where
//     that pixel shows the same plane at a depth within `depth_tolerance` of the point's (not
//     occluded, not another surface);
//   - per point with at least two observations, the population variance of x = (r + g + b) / 3
//     (the supplement's Welford statistic, M_2 / n), and per plane the fraction of points above δ_v;
//   - per plane the mean of the channels' variances, which bounds what modelling reflections can
//     add in PSNR (docs/planes.md "What the input shows").
// A plane is "verifiable" when that fraction exceeds δ_area.
#include "core/common/camera.h"
#include "core/common/image.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <set>
#include <vector>

namespace rrg {

struct PlaneObservedVariance {
  int64_t points = 0;          // points with at least two observations
  double fraction_above = 0;   // of those, the share with variance > δ_v
  double median = 0;           // median variance
  double mean = 0;             // mean variance of x
  double mean_rgb = 0;         // mean over points and channels of each channel's variance: the least
                               // mean squared error (as PSNR counts it) that one colour per point leaves
                               // over its views, i.e. what a model of the view-dependence could remove
  bool verifiable(double delta_area) const { return points > 0 && fraction_above > delta_area; }
};

class ObservedVariance {
 public:
  // Throws std::invalid_argument for a stride < 1 or a tolerance <= 0.
  ObservedVariance(const Intrinsics& K, float depth_tolerance, int stride = 4);
  // One view (an identification frame). Throws std::invalid_argument when an image's size is not K's.
  void add(const Eigen::Isometry3f& T_wc, const DepthImage& depth, const ColorImage& color, const LabelImage& planes);
  // Per plane id of `planes` seen in any view (ids not seen are absent).
  std::map<int, PlaneObservedVariance> stats(const std::set<int>& planes, float delta_v) const;
  size_t views() const { return views_.size(); }

 private:
  struct View {
    Eigen::Isometry3f T_cw;
    Eigen::Isometry3f T_wc;
    DepthImage depth;
    ColorImage color;
    LabelImage planes;
  };
  Intrinsics K_;
  float tolerance_;
  int stride_;
  std::vector<View> views_;
};

}  // namespace rrg
