#pragma once
// Adam for a GaussianSet (paper §4.2.2, supplement "Implementation Details"), on the set's device.
// Per-parameter learning rates (separate defaults for base and reflection Gaussians); only the
// Gaussians visible in the step are updated (3DGS "sparse Adam"): a Gaussian whose gradient is zero
// in every component did not touch any pixel of the rendered view, so its moments, its step count
// and its parameters stay as they are. Bias correction uses a per-Gaussian step count, so Gaussians
// added later start their own schedule. The state follows the set: grow() after append(),
// compact() with the Compaction returned by prune().
#include "core/common/buffer.h"
#include "core/gaussians/gaussian_grads.h"
#include "core/gaussians/gaussian_set.h"

#include <cstdint>
#include <vector>

namespace rrg {

struct AdamLearningRates {
  float mean = 1.6e-4f;      // lr_position
  float log_scale = 5e-3f;   // lr_scale
  float opacity = 5e-2f;     // lr_opacity (base 0.05, reflection 0.001)
  float rotation = 1e-3f;    // lr_rotation
  float sh0 = 2.5e-3f;       // lr_SH0
  float sh_rest = 5e-4f;     // lr_SHrest
  static AdamLearningRates base() { return {}; }
  static AdamLearningRates reflection() {
    AdamLearningRates r;
    r.opacity = 1e-3f;
    return r;
  }
};

struct AdamParams {
  AdamLearningRates lr;
  float beta1 = 0.9f, beta2 = 0.999f;
  float eps = 1e-15f;  // 3DGS
  void validate() const;  // throws std::invalid_argument naming the bad field
};

// Host copy of the state for inspection and tests. Per Gaussian the parameters are laid out as
// mean (3), log-scale (3), quaternion (4), logit opacity (1), SH ([K, 3]).
struct AdamStateHost {
  int stride = 0;
  std::vector<float> m, v;        // [N, stride]
  std::vector<int32_t> steps;     // [N] updates applied to each Gaussian
};

class GaussianAdam {
 public:
  GaussianAdam(const AdamParams& params, int sh_degree, const Device& device);

  size_t size() const { return size_; }
  int stride() const { return stride_; }
  const AdamParams& params() const { return params_; }
  void set_params(const AdamParams& params);

  // State for Gaussians [size(), n) set to zero (call after GaussianSet::append). n >= size().
  void grow(size_t n);
  // Replays a GaussianSet::prune on the state.
  void compact(const Compaction& c);
  // Drops all state (e.g. after loading a map).
  void reset(size_t n);

  // One Adam update of every visible Gaussian of set from grads (same layout). Throws
  // std::invalid_argument when sizes, SH degree or devices disagree. Returns the number updated.
  int64_t step(GaussianSet& set, const GaussianGrads& grads);

  AdamStateHost to_host() const;
  // Replaces the state with a host copy (session snapshots: a restored mapper continues with the
  // moments and step counts it had). Throws std::invalid_argument when the stride or the array
  // lengths disagree.
  void from_host(const AdamStateHost& state);

 private:
  AdamParams params_;
  int sh_coeffs_;
  int stride_;
  Device device_;
  size_t size_ = 0, capacity_ = 0;
  Buffer<float> m_, v_;       // [capacity, stride]
  Buffer<int32_t> steps_;     // [capacity]
};

}  // namespace rrg
