#pragma once
// Gaussian densification (paper §4.2.1, supplement): candidate pixels of one posed frame, a sampled
// subset of them, and new Gaussians initialised from the samples as GPS-SLAM does. Host code over
// host images (a few image-sized passes once per mapping step; the optimisation dominates).
//
// Base G_b:  |C_gt − C| > δ_b and W_b < δ_w,b, and observed depth D_gt > 0. The position is the
//            back-projected observed depth.
// Reflection G_r: R = 1, |C_gt − C| > δ_r, W_r < δ_w,r, and I(u) a plane of L_ref; the paper's
//            per-pixel C_var > δ_v as well only with reflection_variance_gate (see below).
//            Ten Gaussians per sample, evenly spaced 2–8 m past the ray–plane intersection along
//            the viewing ray (virtual space), with the plane id ℓ = I(u).
// |C_gt − C| is the mean absolute difference over the three channels.
//
// Initialisation: scale s = sqrt(mean of the squared distances to the 3 nearest new points of the
// same call), clamped to [min_init_scale, max_init_scale] (neighbours farther than the cap count as
// the cap). The cap is 1 cm for both sets (GPS-SLAM; the paper initialises reflection Gaussians
// "in the same manner as base Gaussians"). The Gaussian is flattened along the surface normal
// (base: normal of the observed depth; reflection: plane normal) to flatten · s; opacity 0.5 (each
// of the S samples along a reflection ray: 1 − 0.5^(1/S), see reflection_sample_opacity); SH DC
// from the colour, higher bands 0.
// Colour = C_gt(u) for both sets (the paper); reflection_residual_color (default) uses max(C_gt − C_b, 0)
// instead (C = C_b + R C_r is additive, so the pixel colour counts the base twice at first).
// min_init_scale keeps a new Gaussian above the prune threshold of its set (else it would be
// removed in the step that created it).
//
// Sampling: a candidate is kept when hash(seed, pixel) < sample_ratio — deterministic, independent
// of threads and order.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/gaussians/gaussian_set.h"
#include "core/gaussians/reflective_plane.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <span>

namespace rrg {

struct DensifyParams {
  float base_error = 0.05f;          // δ_b
  float base_weight = 3.0f;          // δ_w,b
  float reflection_error = 0.05f;    // δ_r
  float variance = 0.01f;            // δ_v
  float reflection_weight = 0.5f;    // δ_w,r
  float sample_ratio = 0.5f;         // fraction of candidate pixels that get Gaussians
  int reflection_samples = 10;       // Gaussians per reflection sample along the ray
  float reflection_near = 2.0f;      // metres past the ray–plane intersection
  float reflection_far = 8.0f;
  float max_init_scale = 0.01f;      // 1 cm cap (GPS-SLAM), base Gaussians
  float reflection_max_init_scale = 0.01f;  // reflection cap: 1 cm, as the base (the paper)
  float base_min_init_scale = 0.0045f;        // 1.5 x the base prune min scale (0.003)
  float reflection_min_init_scale = 0.0075f;  // 1.5 x the reflection prune min scale (0.005)
  float flatten = 0.1f;              // normal-axis scale / tangential scale
  float init_opacity = 0.5f;
  // Opacity of each of the reflection_samples Gaussians along one reflection ray. 0 (default) =
  // derived: the S samples together are as opaque as one new Gaussian, 1 − (1 − init_opacity)^(1/S)
  // (0.067 for S = 10), so that the samples behind the first still receive light and gradient; at
  // 0.5 the first sample takes half the light and the fifth 3 % (mirror_room 640x480: the mirror
  // 2.3 dB below base only with 0.5, 0.2 dB above it derived; docs/mapping.md). A Gaussian at the
  // mirrored surface is one surface and gets init_opacity.
  float reflection_sample_opacity = 0.0f;
  // Reflection colour max(C_gt − C_b, 0) (ours) instead of the paper's C_gt. C = C_b + R·C_r only
  // adds light, so a new reflection Gaussian carries what C_b lacks; with C_gt it overshoots by
  // about its opacity × C_gt wherever C_b already explains the pixel, which on a plane accepted
  // without reflecting (real data, `none` cue) is everywhere: 7-Scenes redkitchen 300 frames,
  // training views −1.38 dB against reflections off with C_gt, +0.01 dB with the residual; the
  // mirror of mirror_room gains less (640x480 harness +5.0 against +5.9 dB; docs/mapping.md).
  bool reflection_residual_color = true;
  bool base_leaves_reflections = false;    // see densify_base (off: on mirror_room it cost 0.4 dB)
  // Reflection positions: false = the paper's samples along the ray 2–8 m past the plane; true =
  // one Gaussian at the mirrored surface (DensifyView::virtual_depth) where it is known.
  bool reflection_mirrored_depth = false;
  // Reflection positions from a plane sweep over the step's other frames (core/slam/reflection_stereo.h):
  // one Gaussian at the most photo-consistent virtual depth (DensifyView::virtual_depth, where the
  // mirrored surface is not known), the paper's samples where no other view sees the pixel's ray.
  // On by default (a departure from the paper's samples, docs/mapping.md): as good or better at
  // every size measured and a ninth of the reflection Gaussians. Without a virtual_depth image in
  // the view (the mapper computes it) densify_reflection places the samples either way.
  bool reflection_stereo_depth = true;
  // The paper's per-pixel C_var > δ_v test for reflection candidates. Off by default: the plane
  // already passed the variance vote (δ_area) to enter L_ref and R marks its reflective region,
  // while a mirror that reflects a uniform surface has no temporal variance there. With the gate,
  // C_var > δ_v held on about half the mirror of mirror_room; base Gaussians took the rest with the
  // TSDF's average reflection, a haze over the whole mirror (docs/mapping.md: held-out reflective
  // pixels +1.3 dB over base only with the gate, +2.4 dB without it, both with a 10 cm scale cap).
  bool reflection_variance_gate = false;
  void validate() const;             // throws std::invalid_argument naming the bad field
  float reflection_sample_alpha() const;  // reflection_sample_opacity, or the derived value for 0
};

// What densification reads of one frame (host images, all K's size; null where not needed).
struct DensifyView {
  Intrinsics K;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
  const ColorImage* C_gt = nullptr;     // input colour
  const DepthImage* D_gt = nullptr;     // input depth (base)
  const ColorImage* C = nullptr;        // rendered C = C_b + R C_r
  const ColorImage* C_b = nullptr;      // rendered base colour (reflection colour init)
  const Image<float>* W_b = nullptr;    // W_g, base Gaussian weight
  const Image<float>* W_r = nullptr;    // reflection Gaussian weight
  const MaskImage* R = nullptr;         // reflection mask
  const Image<float>* C_var = nullptr;  // TSDF colour variance
  const Image<int32_t>* I = nullptr;    // plane ids
  // optional: depth of the virtual point behind the plane (the mirrored surface, mirror_depth.h, or
  // the plane sweep, reflection_stereo.h); 0 where unknown
  const Image<float>* virtual_depth = nullptr;
};

// With `reflective` planes given (and params.base_leaves_reflections), the pixels that the
// reflection set may take (R = 1 on one of those planes, and C_var > δ_v with the variance gate)
// get no base Gaussians: their error is the reflection's to fit.
GaussianHost densify_base(const DensifyView& view, const DensifyParams& params, int sh_degree, uint64_t seed,
                          std::span<const ReflectivePlane> reflective = {});
GaussianHost densify_reflection(const DensifyView& view, std::span<const ReflectivePlane> planes,
                                const DensifyParams& params, int sh_degree, uint64_t seed);
// The pixels densify_reflection() samples with the same arguments (every test but the placement):
// where a virtual depth is worth computing (view.virtual_depth is not read).
MaskImage reflection_candidates(const DensifyView& view, std::span<const ReflectivePlane> planes,
                                const DensifyParams& params, uint64_t seed);

// The shared initialisation: points (world), unit normals along which to flatten, colours, plane ids
// and opacities in (0, 1), one per point.
GaussianHost init_gaussians(std::span<const Eigen::Vector3f> points, std::span<const Eigen::Vector3f> normals,
                            std::span<const Color> colors, std::span<const int32_t> plane_ids,
                            std::span<const float> opacities, const DensifyParams& params, float min_init_scale,
                            float max_init_scale, int sh_degree);

}  // namespace rrg
