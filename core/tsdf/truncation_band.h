#pragma once
// The truncation band of a depth observation: ε(d) = max(ε, k σ_n(d)).
//
// ε is the paper's truncation (GPS-SLAM's 2 cm). A band narrower than the sensor's noise biases
// the surface: fusion skips the observations that fall more than the band behind a voxel (sdf < −ε)
// and clips those in front of it to +1, so where σ_n(d) is close to ε (Kinect-like noise passes 1 cm
// at 2.5 m and 2 cm at 3.5 m) the average of what is kept sits in front of the voxel and the zero
// crossing moves away from the camera. With a band of k = 3 standard deviations, 99.7 % of a
// surface's observations land inside it (a Gaussian's mass within 3σ). Nearer than the depth where
// k σ_n(d) = ε (2.1 m with the defaults) the band is the paper's ε; k = 0 is the constant band everywhere.
//
// Fusion stores t = min(1, sdf / ε(d)), so one voxel may hold averages of distances normalised by
// different bands; its zero crossing, which is what raycasting and meshing read, stays an unbiased
// estimate of the surface (each observation's sdf / ε(d) has the sign of its sdf), and far
// observations weigh 1 / ε(d) as much as near ones, in step with their noise. The raycast steps by
// f · ε, which is at most the distance to the surface when the band was wider (a shorter step,
// never an overshoot).
#include "core/common/depth_noise_model.h"
#include "core/common/hd.h"

namespace rrg {

struct TruncationBand {
  float eps = 0.02f;      // ε, metres: the band's floor
  float sigmas = 3.0f;    // k; 0: ε at every depth
  DepthNoiseModel noise;  // σ_n(d)
  RRG_HD float at(float d) const {
    const float w = sigmas * noise.sigma(d);
    return w > eps ? w : eps;
  }
};

}  // namespace rrg
