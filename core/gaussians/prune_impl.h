#pragma once
// The body of prune_mask, templated on the back end; instantiated by prune_cpu.cpp, prune_cuda.cu.
#include "core/common/span.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace rrg::kernel {

struct PruneArgs {
  float min_opacity, min_scale, max_scale;
};

// x is neither NaN nor ±inf (no <cmath> isfinite: it differs between host and device headers).
RRG_HD inline bool finite_f(float x) { return x == x && fabsf(x) <= 3.4028234e38f; }
RRG_HD inline bool finite3(const Eigen::Vector3f& v) { return finite_f(v.x()) && finite_f(v.y()) && finite_f(v.z()); }

template <class Backend>
void prune_mask(Backend be, PruneArgs a, Span<const Eigen::Vector3f> means, Span<const Eigen::Vector3f> log_scales,
                Span<const Eigen::Vector4f> quats, Span<const float> logit_opacities, Span<uint8_t> keep) {
  parallel_for(be, means.size, [=] RRG_HD(int64_t i) {
    const float sigma = 1.0f / (1.0f + expf(-logit_opacities[i]));
    const Eigen::Vector3f ls = log_scales[i];
    const float s = expf(fmaxf(ls.x(), fmaxf(ls.y(), ls.z())));
    const Eigen::Vector4f q = quats[i];
    const bool ok = finite3(means[i]) && finite3(ls) && finite_f(q.x()) && finite_f(q.y()) && finite_f(q.z()) &&
                    finite_f(q.w()) && q.squaredNorm() > 0.0f && finite_f(logit_opacities[i]);
    keep[i] = (ok && sigma >= a.min_opacity && s >= a.min_scale && s <= a.max_scale) ? 1 : 0;
  });
}

void prune_mask_cpu(const PruneArgs& a, Span<const Eigen::Vector3f> means, Span<const Eigen::Vector3f> log_scales,
                    Span<const Eigen::Vector4f> quats, Span<const float> logit_opacities, Span<uint8_t> keep);
void prune_mask_cuda(const PruneArgs& a, Span<const Eigen::Vector3f> means, Span<const Eigen::Vector3f> log_scales,
                     Span<const Eigen::Vector4f> quats, Span<const float> logit_opacities, Span<uint8_t> keep);

}  // namespace rrg::kernel
