#include "core/eval/mesh_metrics.h"

#include "core/eval/surface_sampling.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace rrg::eval {
namespace {

constexpr double kCm = 100.0;

struct DistanceSummary {
  double mean_m = 0.0;
  double fraction_below = 0.0;
};

DistanceSummary summarise(const std::vector<double>& d, double threshold) {
  double sum = 0.0;
  size_t below = 0;
  for (double v : d) {
    sum += v;
    below += v < threshold ? 1 : 0;
  }
  return {sum / double(d.size()), double(below) / double(d.size())};
}

}  // namespace

std::vector<double> nearest_distances(const KdTree& tree, std::span<const Eigen::Vector3f> queries) {
  std::vector<double> out(queries.size());
  const auto n = static_cast<std::int64_t>(queries.size());
#pragma omp parallel for schedule(dynamic, 1024) if (n >= 4096)
  for (std::int64_t i = 0; i < n; ++i) out[i] = std::sqrt(double(tree.nearest(queries[i]).distance_sq));
  return out;
}

MeshMetrics evaluate_point_sets(std::span<const Eigen::Vector3f> est, std::span<const Eigen::Vector3f> ref,
                                double threshold) {
  if (est.empty()) throw std::invalid_argument("mesh metrics: estimated point set is empty");
  if (ref.empty()) throw std::invalid_argument("mesh metrics: reference point set is empty");
  if (!(threshold > 0.0) || !std::isfinite(threshold))
    throw std::invalid_argument("mesh metrics: threshold must be a positive number of metres");

  const KdTree ref_tree({ref.begin(), ref.end()});
  const KdTree est_tree({est.begin(), est.end()});
  const DistanceSummary acc = summarise(nearest_distances(ref_tree, est), threshold);
  const DistanceSummary comp = summarise(nearest_distances(est_tree, ref), threshold);

  MeshMetrics out;
  out.est_samples = est.size();
  out.ref_samples = ref.size();
  out.threshold_m = threshold;
  out.accuracy_cm = kCm * acc.mean_m;
  out.accuracy_ratio = acc.fraction_below;
  out.completion_cm = kCm * comp.mean_m;
  out.completion_ratio = comp.fraction_below;
  return out;
}

MeshMetrics evaluate_mesh(const TriangleMesh& est, const TriangleMesh& ref, const MeshEvalParams& params) {
  if (params.samples == 0) throw std::invalid_argument("mesh metrics: number of samples must be positive");
  std::vector<Eigen::Vector3f> est_points, ref_points;
  try {
    est_points = sample_surface(est, params.samples, params.seed);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("estimated mesh: ") + e.what());
  }
  try {
    ref_points = sample_surface(ref, params.samples, params.seed + 1);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("reference mesh: ") + e.what());
  }
  return evaluate_point_sets(est_points, ref_points, params.threshold);
}

}  // namespace rrg::eval
