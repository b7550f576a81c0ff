#pragma once
// Small shading functions of the synthetic renderer, exposed so tests can check them directly.
#include "core/common/image.h"

#include <algorithm>
#include <cmath>

namespace rrg::synth {

// Schlick's Fresnel approximation: F = F0 + (1 - F0) (1 - cos θ)^5, cos θ clamped to [0,1].
inline float fresnel_schlick(float f0, float cos_theta) {
  const float m = 1.0f - std::clamp(cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  return f0 + (1.0f - f0) * m2 * m2 * m;
}

// Display mapping applied once per pixel at the end: exponential tone curve then gamma 2.2.
// Monotonic, 0 -> 0, saturates smoothly towards 1.
inline float tone_map(float linear, float exposure) {
  const float x = 1.0f - std::exp(-exposure * std::max(linear, 0.0f));
  return std::pow(x, 1.0f / 2.2f);
}
inline Color tone_map(const Color& c, float exposure) {
  return {tone_map(c.x(), exposure), tone_map(c.y(), exposure), tone_map(c.z(), exposure)};
}

// Wrapped Lambert term: soft diffuse falloff that reaches 0 slightly past the terminator.
inline float wrapped_lambert(float n_dot_l, float wrap = 0.25f) {
  return std::max(0.0f, (n_dot_l + wrap) / (1.0f + wrap));
}

}  // namespace rrg::synth
