#pragma once
// Optional camera model for synthetic colour: auto-exposure. Every trajectory frame's colour is
// scaled by a gain that drifts smoothly with time, then clipped to [0, 1] as a camera's output is:
//   g(t) = exp(A · (0.6 sin(2π t / 1.7 s + φ1) + 0.4 sin(2π t / 4.3 s + φ2))),  A = ln 1.35
// so g stays within [1/1.35, 1.35] and moves by up to ~30 % within a second, as the 7-Scenes
// Kinect v1 frames do (docs/synth.md). φ1, φ2 come from the seed. Held-out views keep g = 1 (the
// reference exposure their scores are against).
#include "core/common/image.h"

#include <cstdint>

namespace rrg::synth {

inline constexpr float kExposureAmplitude = 0.30010459f;  // ln 1.35

// The gain of the frame at time t (seconds) for a seed.
float exposure_gain(double t, uint32_t seed);

// colour ← min(1, g · colour), in place.
void apply_exposure(ColorImage& color, float gain);

}  // namespace rrg::synth
