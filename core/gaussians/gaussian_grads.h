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
  // [N] 1 where some gradient of Gaussian i is non-zero (the Gaussians a view saw), 0 elsewhere;
  // written by the renderer's backward. Empty when unknown: GaussianAdam then reads the gradients.
  // When it is given, the gradient of a Gaussian marked 0 is zero whatever its v_* entries hold:
  // the renderer's backward leaves those unwritten (most of a large map is out of any one view),
  // so readers go through the marks, as GaussianAdam does.
  Buffer<uint8_t> touched;

  // Zero gradients for n Gaussians with k SH coefficients each, on device (reuses memory when the
  // sizes already match); `touched` is left empty.
  void reset(size_t n, int k, const Device& device);
  // Buffers (touched included) for n Gaussians with k SH coefficients, contents left as they are:
  // for a writer that sets every mark and the entries of the marked (the renderer's backward).
  // Reuses memory when sizes match.
  void resize(size_t n, int k, const Device& device);
};

}  // namespace rrg
