#pragma once
// Optional sensor model for synthetic depth: Kinect-like distance-dependent Gaussian noise
// sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 metres, dropouts next to depth discontinuities, and
// invalid depth on mirror-like surfaces (F0 > 0.5). Deterministic: every random draw is a hash of
// (pixel, frame, seed).
#include "core/common/image.h"
#include "core/synth/scene.h"

#include <cstdint>

namespace rrg::synth {

struct DepthNoiseParams {
  bool gaussian = false;          // add sigma(z) noise
  bool edge_dropout = false;      // drop pixels next to discontinuities
  float edge_jump = 0.05f;        // metres (relative to z): neighbour difference that counts as an edge
  float edge_drop_probability = 0.5f;
  bool invalid_on_mirrors = false;  // 0 depth where the first surface has F0 > mirror_f0
  float mirror_f0 = 0.5f;
};

// Kinect-like axial noise standard deviation at depth z (metres): DepthNoiseModel{}.sigma(z).
float kinect_sigma(float z);

// Applies the model in place. material holds material index + 1 per pixel (RenderOutput::material).
void apply_depth_noise(DepthImage& depth, const Image<uint16_t>& material, const Scene& scene,
                       const DepthNoiseParams& params, uint32_t frame, uint32_t seed);

}  // namespace rrg::synth
