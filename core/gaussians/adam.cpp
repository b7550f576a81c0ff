#include "core/gaussians/adam.h"

#include "core/common/dispatch.h"
#include "core/gaussians/adam_impl.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rrg {

namespace {

template <class T>
void regrow(Buffer<T>& b, size_t count, size_t keep, const Device& device) {
  Buffer<T> grown(count, device);
  mem::copy(grown.data(), device, b.data(), device, keep * sizeof(T));
  b = std::move(grown);
}

template <class T>
Span<uint32_t> words_of(Buffer<T>& b) {
  static_assert(sizeof(T) == 4);
  return {reinterpret_cast<uint32_t*>(b.data()), int64_t(b.size())};
}

}  // namespace

void AdamParams::validate() const {
  auto positive = [](float v, const char* name) {
    if (!(v >= 0.0f)) throw std::invalid_argument(std::string("AdamParams: ") + name + " = " + std::to_string(v) + " < 0");
  };
  positive(lr.mean, "lr.mean");
  positive(lr.log_scale, "lr.log_scale");
  positive(lr.opacity, "lr.opacity");
  positive(lr.rotation, "lr.rotation");
  positive(lr.sh0, "lr.sh0");
  positive(lr.sh_rest, "lr.sh_rest");
  if (!(beta1 >= 0.0f && beta1 < 1.0f)) throw std::invalid_argument("AdamParams: beta1 outside [0, 1)");
  if (!(beta2 >= 0.0f && beta2 < 1.0f)) throw std::invalid_argument("AdamParams: beta2 outside [0, 1)");
  if (!(eps >= 0.0f)) throw std::invalid_argument("AdamParams: eps < 0");
}

GaussianAdam::GaussianAdam(const AdamParams& params, int sh_degree, const Device& device)
    : params_(params), sh_coeffs_(sh_coeff_count(sh_degree)), stride_(11 + 3 * sh_coeffs_), device_(device) {
  params_.validate();
  if (sh_degree < 0 || sh_degree > kMaxShDegree)
    throw std::invalid_argument("GaussianAdam: SH degree " + std::to_string(sh_degree) + " outside [0, 3]");
}

void GaussianAdam::set_params(const AdamParams& params) {
  params.validate();
  params_ = params;
}

void GaussianAdam::grow(size_t n) {
  if (n < size_)
    throw std::invalid_argument("GaussianAdam::grow: " + std::to_string(n) + " < current size " + std::to_string(size_));
  if (n > capacity_) {
    const size_t cap = std::max(n, capacity_ + capacity_ / 2);
    regrow(m_, cap * stride_, size_ * stride_, device_);
    regrow(v_, cap * stride_, size_ * stride_, device_);
    regrow(steps_, cap, size_, device_);
    capacity_ = cap;
  }
  if (n > size_) {
    const size_t s = size_t(stride_);
    mem::fill_zero(m_.data() + size_ * s, (n - size_) * s * sizeof(float), device_);
    mem::fill_zero(v_.data() + size_ * s, (n - size_) * s * sizeof(float), device_);
    mem::fill_zero(steps_.data() + size_, (n - size_) * sizeof(int32_t), device_);
  }
  size_ = n;
}

void GaussianAdam::compact(const Compaction& c) {
  if (c.old_size != size_)
    throw std::invalid_argument("GaussianAdam::compact: compaction of " + std::to_string(c.old_size) +
                                " Gaussians, state holds " + std::to_string(size_));
  apply_compaction(c, words_of(m_), stride_, device_);
  apply_compaction(c, words_of(v_), stride_, device_);
  apply_compaction(c, words_of(steps_), 1, device_);
  size_ = c.new_size;
}

void GaussianAdam::reset(size_t n) {
  size_ = 0;
  grow(n);
}

int64_t GaussianAdam::step(GaussianSet& set, const GaussianGrads& g) {
  const size_t n = set.size();
  if (n != size_)
    throw std::invalid_argument("GaussianAdam::step: set has " + std::to_string(n) + " Gaussians, state " +
                                std::to_string(size_) + " (call grow/compact after append/prune)");
  if (set.sh_coeffs() != sh_coeffs_) throw std::invalid_argument("GaussianAdam::step: SH degree differs from the state's");
  if (set.device() != device_) throw std::invalid_argument("GaussianAdam::step: set on " + set.device().to_string() +
                                                           ", state on " + device_.to_string());
  if (g.v_means.size() != n || g.v_log_scales.size() != n || g.v_quats.size() != n || g.v_logit_opacities.size() != n ||
      g.v_sh.size() != n * size_t(sh_coeffs_))
    throw std::invalid_argument("GaussianAdam::step: gradients are not sized like the set");
  if (!g.touched.empty() && g.touched.size() != n)
    throw std::invalid_argument("GaussianAdam::step: `touched` has " + std::to_string(g.touched.size()) +
                                " entries, the set " + std::to_string(n));
  if (n == 0) return 0;
  const kernel::AdamArgs a{params_.lr.mean, params_.lr.log_scale, params_.lr.opacity, params_.lr.rotation,
                           params_.lr.sh0,  params_.lr.sh_rest,   params_.beta1,      params_.beta2,
                           params_.eps,     sh_coeffs_,           stride_};
  const kernel::AdamTensors t{set.means(),         set.log_scales(),        set.quats(),
                              set.logit_opacities(), set.sh(),              g.v_means.span(),
                              g.v_log_scales.span(), g.v_quats.span(),      g.v_logit_opacities.span(),
                              g.v_sh.span(),       g.touched.span(),        m_.span(),
                              v_.span(),           steps_.span()};
  int64_t updated = 0;
  RRG_DISPATCH(device_, updated = kernel::adam_step_cpu(int64_t(n), a, t),
               updated = kernel::adam_step_cuda(int64_t(n), a, t));
  return updated;
}

AdamStateHost GaussianAdam::to_host() const {
  AdamStateHost h;
  h.stride = stride_;
  const size_t s = size_t(stride_);
  h.m.resize(size_ * s);
  h.v.resize(size_ * s);
  h.steps.resize(size_);
  mem::copy(h.m.data(), Device::cpu(), m_.data(), device_, size_ * s * sizeof(float));
  mem::copy(h.v.data(), Device::cpu(), v_.data(), device_, size_ * s * sizeof(float));
  mem::copy(h.steps.data(), Device::cpu(), steps_.data(), device_, size_ * sizeof(int32_t));
  return h;
}

void GaussianAdam::from_host(const AdamStateHost& h) {
  if (h.stride != stride_)
    throw std::invalid_argument("GaussianAdam::from_host: state stride " + std::to_string(h.stride) + ", expected " +
                                std::to_string(stride_) + " (SH degree differs)");
  const size_t n = h.steps.size(), s = size_t(stride_);
  if (h.m.size() != n * s || h.v.size() != n * s)
    throw std::invalid_argument("GaussianAdam::from_host: moments of " + std::to_string(h.m.size()) + " / " +
                                std::to_string(h.v.size()) + " floats for " + std::to_string(n) +
                                " Gaussians of stride " + std::to_string(stride_));
  reset(n);
  mem::copy(m_.data(), device_, h.m.data(), Device::cpu(), n * s * sizeof(float));
  mem::copy(v_.data(), device_, h.v.data(), Device::cpu(), n * s * sizeof(float));
  mem::copy(steps_.data(), device_, h.steps.data(), Device::cpu(), n * sizeof(int32_t));
}

}  // namespace rrg
