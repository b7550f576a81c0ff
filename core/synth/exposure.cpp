#include "core/synth/exposure.h"

#include "core/synth/hash.h"

#include <cmath>
#include <numbers>

namespace rrg::synth {

float exposure_gain(double t, uint32_t seed) {
  const double two_pi = 2.0 * std::numbers::pi;
  const double phi1 = two_pi * unit_float(hash3(seed, 0xe790u, 1)), phi2 = two_pi * unit_float(hash3(seed, 0xe790u, 2));
  const double s = 0.6 * std::sin(two_pi * t / 1.7 + phi1) + 0.4 * std::sin(two_pi * t / 4.3 + phi2);
  return float(std::exp(double(kExposureAmplitude) * s));
}

void apply_exposure(ColorImage& color, float gain) {
  for (Color& c : color.pixels()) c = (gain * c).cwiseMin(1.0f);
}

}  // namespace rrg::synth
