#include "core/gaussians/gaussian_grads.h"

namespace rrg {

namespace {
template <class T>
void sized(Buffer<T>& b, size_t n, const Device& device) {
  if (b.size() != n || b.device() != device) b = Buffer<T>(n, device);
}

// f(buffer, entries) for each gradient buffer of n Gaussians with k SH coefficients.
template <class F>
void for_each_gradient(GaussianGrads& g, size_t n, int k, F&& f) {
  f(g.v_means, n);
  f(g.v_log_scales, n);
  f(g.v_quats, n);
  f(g.v_logit_opacities, n);
  f(g.v_sh, n * size_t(k));
}
}  // namespace

void GaussianGrads::reset(size_t n, int k, const Device& device) {
  for_each_gradient(*this, n, k, [&](auto& b, size_t m) {
    sized(b, m, device);
    b.fill_zero();
  });
  touched = Buffer<uint8_t>();
}

void GaussianGrads::resize(size_t n, int k, const Device& device) {
  for_each_gradient(*this, n, k, [&](auto& b, size_t m) { sized(b, m, device); });
  sized(touched, n, device);
}

}  // namespace rrg
