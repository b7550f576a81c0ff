#pragma once
// Depth of the virtual scene behind reflective planes from the mapping step's own frames: a
// plane sweep (multi-view photo-consistency) along each reflection ray, where the paper places ten
// samples 2–8 m past the plane and lets the optimisation sort them out.
//
// Why: the reflected content is a virtual scene at a definite depth behind the plane (paper §3), so
// a Gaussian at the wrong depth projects to different pixels in the other training views. The
// error is the parallax f_x · b · |1/z − 1/z'| pixels, which grows with the resolution, and the
// paper's samples are 0.67 m apart; at 512x384 the fit smears the reflection along the camera's
// motion. On by default (densify.reflection_stereo_depth): on mirror_room's harness +0.4 dB at
// 256x192 and +1.1 dB at 512x384 over the samples on held-out mirror pixels, with a ninth of the
// reflection Gaussians (docs/mapping.md, "At 640x480 reflections lost").
//
// For a reference pixel u on plane ℓ (I(u) = ℓ), the ray from the camera centre o along d meets the
// plane at distance t_0; hypotheses X(t) = o + t d for t in [t_0 + near, t_0 + far], evenly spaced
// in 1/t (even steps in disparity), as many as the widest other view needs for about one pixel per
// step (at most max_hypotheses). Each hypothesis is projected into the other views; a view counts
// where the projection lands inside the image on a pixel of the same plane (it sees X through the
// plane) and costs the summed absolute colour difference of the (2r+1)² patches around u and around
// the projection (bilinear). The hypothesis with the least mean cost over its views wins, refined
// by a parabola through its neighbours; pixels no other view sees through the plane get 0.
// Host code over host images, like densification (core/gaussians/densify.h): rows in parallel,
// deterministic for any number of threads.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/gaussians/reflective_plane.h"

#include <Eigen/Geometry>

#include <span>

namespace rrg {

struct ReflectionStereoParams {
  float near = 0.05f;        // metres past the plane (the virtual scene starts at the plane)
  float far = 8.0f;          // metres past the plane (the paper's far end of the samples)
  int max_hypotheses = 96;   // per pixel
  int min_hypotheses = 16;
  int max_views = 4;         // other views compared per reference view (the nearest by baseline)
  float min_baseline = 0.01f;  // metres: closer views constrain nothing
  int patch_radius = 2;      // 5x5 patches (3x3: 0.4 dB less at 512x384, docs/mapping.md)
  void validate() const;     // throws std::invalid_argument naming the bad field
};

struct StereoView {                  // another posed frame of the step (host images, same K)
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  const ColorImage* C = nullptr;     // its input colour C_gt
  const Image<int32_t>* I = nullptr; // its plane ids (pass 1)
};

// Per pixel of the reference view (K, T_wc, C, I) where `want` is non-zero (null: every pixel) and
// I(u) is one of `planes`: the depth along the optical axis of the most photo-consistent virtual
// point behind the plane, as mirrored_depth() gives it (core/slam/mirror_depth.h); 0 elsewhere.
// Uses at most params.max_views of `others`, the nearest with a baseline >= min_baseline.
Image<float> reflection_stereo_depth(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const ColorImage& C,
                                     const Image<int32_t>& I, const MaskImage* want,
                                     std::span<const ReflectivePlane> planes, std::span<const StereoView> others,
                                     const ReflectionStereoParams& params);

}  // namespace rrg
