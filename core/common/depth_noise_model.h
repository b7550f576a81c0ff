#pragma once
// The axial noise of a structured-light RGB-D sensor (Kinect v1; Nguyen, Izadi & Lovell 2012):
// σ_n(z) = a + b (z − z0)², metres. One model for what the method assumes (plane segmentation's
// cell fit and refinement, the reflective fill's inlier band) and what the synthetic sensor adds.
#include "core/common/hd.h"

#include <cmath>

namespace rrg {

struct DepthNoiseModel {
  float a = 0.0012f;  // metres
  float b = 0.0019f;  // 1/m
  float z0 = 0.4f;    // metres
  RRG_HD float sigma(float z) const { return a + b * (z - z0) * (z - z0); }  // σ_n(z); on both back ends (ICP)
  bool valid() const { return a >= 0.0f && b >= 0.0f && std::isfinite(a + b + z0); }  // a, b >= 0, all finite
};

}  // namespace rrg
