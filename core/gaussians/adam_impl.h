#pragma once
// The body of GaussianAdam::step, templated on the back end; instantiated by adam_cpu.cpp and
// adam_cuda.cu. One work item per Gaussian.
#include "core/common/span.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace rrg::kernel {

struct AdamArgs {
  float lr_mean, lr_scale, lr_opacity, lr_rotation, lr_sh0, lr_sh_rest;
  float beta1, beta2, eps;
  int sh_coeffs;  // K
  int stride;     // 11 + 3K
};

struct AdamTensors {
  Span<Eigen::Vector3f> means, log_scales;     // [N]
  Span<Eigen::Vector4f> quats;                 // [N]
  Span<float> logit_opacities;                 // [N]
  Span<Eigen::Vector3f> sh;                    // [N, K]
  Span<const Eigen::Vector3f> v_means, v_log_scales;
  Span<const Eigen::Vector4f> v_quats;
  Span<const float> v_logit_opacities;
  Span<const Eigen::Vector3f> v_sh;
  Span<const uint8_t> touched;                 // [N] or empty (then the gradients are read)
  Span<float> m, v;                            // [N, stride]
  Span<int32_t> steps;                         // [N]
};

// m ← β1 m + (1 − β1) g; v ← β2 v + (1 − β2) g²; p ← p − lr (m / (1 − β1^t)) / (sqrt(v / (1 − β2^t)) + ε)
RRG_HD inline void adam_update(float& p, float g, float& m, float& v, float lr, const AdamArgs& a, float bc1,
                               float bc2) {
  m = a.beta1 * m + (1.0f - a.beta1) * g;
  v = a.beta2 * v + (1.0f - a.beta2) * g * g;
  p -= lr * (m / bc1) / (sqrtf(v / bc2) + a.eps);
}

template <class Backend>
int64_t adam_step(Backend be, int64_t n, AdamArgs a, AdamTensors t) {
  // The map updates Gaussian i (each index is mapped exactly once) and counts it when visible: some
  // gradient non-zero, as `touched` records (read from the gradients when it is not given).
  return parallel_reduce(
      be, n, int64_t(0),
      [=] RRG_HD(int64_t i) -> int64_t {
        const int K = a.sh_coeffs;
        bool visible = false;
        if (!t.touched.empty()) {
          visible = t.touched[i] != 0;
        } else {
          visible = t.v_logit_opacities[i] != 0.0f;
          for (int c = 0; c < 3; ++c)
            visible = visible || t.v_means[i][c] != 0.0f || t.v_log_scales[i][c] != 0.0f;
          for (int c = 0; c < 4; ++c) visible = visible || t.v_quats[i][c] != 0.0f;
          for (int k = 0; k < K && !visible; ++k)
            for (int c = 0; c < 3; ++c) visible = visible || t.v_sh[i * K + k][c] != 0.0f;
        }
        if (!visible) return 0;
        const int32_t step = t.steps[i] + 1;
        t.steps[i] = step;
        const float bc1 = 1.0f - powf(a.beta1, float(step)), bc2 = 1.0f - powf(a.beta2, float(step));
        float* m = &t.m[i * a.stride];
        float* v = &t.v[i * a.stride];
        int j = 0;
        for (int c = 0; c < 3; ++c, ++j) adam_update(t.means[i][c], t.v_means[i][c], m[j], v[j], a.lr_mean, a, bc1, bc2);
        for (int c = 0; c < 3; ++c, ++j)
          adam_update(t.log_scales[i][c], t.v_log_scales[i][c], m[j], v[j], a.lr_scale, a, bc1, bc2);
        for (int c = 0; c < 4; ++c, ++j)
          adam_update(t.quats[i][c], t.v_quats[i][c], m[j], v[j], a.lr_rotation, a, bc1, bc2);
        adam_update(t.logit_opacities[i], t.v_logit_opacities[i], m[j], v[j], a.lr_opacity, a, bc1, bc2);
        ++j;
        // The SH coefficients as one run of 3K floats (Vector3f has no padding): the DC band's three
        // with lr_sh0, then the rest with lr_sh_rest, a plain loop the host compiler vectorises.
        float* sh = t.sh[i * K].data();
        const float* v_sh = t.v_sh[i * K].data();
        for (int q = 0; q < 3; ++q) adam_update(sh[q], v_sh[q], m[j + q], v[j + q], a.lr_sh0, a, bc1, bc2);
        for (int q = 3; q < 3 * K; ++q) adam_update(sh[q], v_sh[q], m[j + q], v[j + q], a.lr_sh_rest, a, bc1, bc2);
        return 1;
      },
      [] RRG_HD(int64_t x, int64_t y) { return x + y; });
}

int64_t adam_step_cpu(int64_t n, const AdamArgs& a, const AdamTensors& t);
int64_t adam_step_cuda(int64_t n, const AdamArgs& a, const AdamTensors& t);

}  // namespace rrg::kernel
