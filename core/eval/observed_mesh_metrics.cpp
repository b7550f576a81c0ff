#include "core/eval/observed_mesh_metrics.h"

#include "core/eval/observed_surface.h"
#include "core/eval/surface_sampling.h"

#include <algorithm>

namespace rrg::eval {

ObservedMeshMetrics evaluate_mesh_observed(const TriangleMesh& est, const TriangleMesh& gt, const io::Dataset& frames,
                                           size_t max_frames, const MeshEvalParams& params, double tolerance_m,
                                           const std::function<void(size_t, size_t)>& progress) {
  const std::vector<Eigen::Vector3f> est_points = sample_surface(est, params.samples, params.seed);
  const OrientedSamples gt_samples = sample_surface_oriented(gt, params.samples, params.seed + 1);
  ObservedMeshMetrics out;
  out.whole = evaluate_point_sets(est_points, gt_samples.points, params.threshold);
  ObservedSurface seen(gt_samples.points, tolerance_m, gt_samples.normals);
  const size_t n = max_frames > 0 ? std::min(max_frames, frames.size()) : frames.size();
  for (size_t i = 0; i < n; ++i) {
    const io::Frame f = frames.load(i);
    if (f.T_wc_gt) {
      seen.observe(f.depth, frames.intrinsics(), *f.T_wc_gt);
      ++out.frames;
    }
    if (progress) progress(i + 1, n);
  }
  out.observed_fraction = seen.size() > 0 ? double(seen.observed()) / double(seen.size()) : 0.0;
  if (seen.observed() > 0) out.observed = evaluate_point_sets(est_points, seen.observed_points(), params.threshold);
  return out;
}

}  // namespace rrg::eval
