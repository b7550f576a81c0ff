#include "core/gaussians/gaussian_grads.h"

namespace rrg {

namespace {
template <class T>
void sized(Buffer<T>& b, size_t n, const Device& device) {
  if (b.size() != n || b.device() != device) b = Buffer<T>(n, device);
}
template <class T>
void zeros(Buffer<T>& b, size_t n, const Device& device) {
  sized(b, n, device);
  b.fill_zero();
}
}  // namespace

void GaussianGrads::reset(size_t n, int k, const Device& device) {
  zeros(v_means, n, device);
  zeros(v_log_scales, n, device);
  zeros(v_quats, n, device);
  zeros(v_logit_opacities, n, device);
  zeros(v_sh, n * size_t(k), device);
  touched = Buffer<uint8_t>();
}

void GaussianGrads::resize(size_t n, int k, const Device& device) {
  sized(v_means, n, device);
  sized(v_log_scales, n, device);
  sized(v_quats, n, device);
  sized(v_logit_opacities, n, device);
  sized(v_sh, n * size_t(k), device);
  sized(touched, n, device);
}

}  // namespace rrg
