#pragma once
// Gradients of a loss with respect to every parameter of a GaussianSet, same layout (v_* naming as
// gsplat). Filled by the renderer's backward pass (core/render/renderer.h).
#include "core/common/buffer.h"

#include <Eigen/Core>

namespace rrg {

struct GaussianGrads {
  Buffer<Eigen::Vector3f> v_means;            // [N, 3]
  Buffer<Eigen::Vector3f> v_log_scales;       // [N, 3]
  Buffer<Eigen::Vector4f> v_quats;            // [N, 4] w.r.t. the stored (unnormalised) quaternion
  Buffer<float> v_logit_opacities;            // [N]
  Buffer<Eigen::Vector3f> v_sh;               // [N, K, 3]

  // Zero gradients for n Gaussians with k SH coefficients each, on device (reuses memory when the
  // sizes already match).
  void reset(size_t n, int k, const Device& device);
};

}  // namespace rrg
