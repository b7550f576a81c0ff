#pragma once
// Geometry of a reconstruction on the surface its input observed (docs/evaluation.md): accuracy over
// the whole estimated mesh, completion over the ground-truth samples some frame saw (ObservedSurface,
// with the ground truth's winding normals), as NICE-SLAM's and Co-SLAM's unseen-region culling.
// `rrg run` and `rrg eval mesh --observed-by` both score through this one function.
#include "core/common/mesh.h"
#include "core/eval/mesh_metrics.h"
#include "core/io/dataset.h"

#include <cstddef>
#include <functional>
#include <optional>

namespace rrg::eval {

// A ground-truth sample counts as observed by a frame when the frame's measured depth at its pixel
// is within this of its own depth: wide enough for Kinect-like noise (σ ≈ 2.5 cm at 4 m).
inline constexpr double kObservedDepthTolerance = 0.05;

struct ObservedMeshMetrics {
  MeshMetrics whole;                    // accuracy (and the whole-mesh completion) against all of gt
  std::optional<MeshMetrics> observed;  // completion over the observed samples; empty when none
  double observed_fraction = 0.0;       // of the ground-truth samples
  size_t frames = 0;                    // frames with a ground-truth pose that were looked at
};

// Observes gt with every frame that has a ground-truth pose among the first max_frames of `frames`
// (0 = all), calling progress(done, total) after each when given. Throws std::invalid_argument from
// sampling (empty or broken meshes).
ObservedMeshMetrics evaluate_mesh_observed(const TriangleMesh& est, const TriangleMesh& gt, const io::Dataset& frames,
                                           size_t max_frames, const MeshEvalParams& params = {},
                                           double tolerance_m = kObservedDepthTolerance,
                                           const std::function<void(size_t, size_t)>& progress = {});

}  // namespace rrg::eval
