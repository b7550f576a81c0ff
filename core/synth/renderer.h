#pragma once
// CPU ray tracer for synthetic RGB-D frames: pinhole camera rays (OpenCV convention), diffuse
// shading from point lights plus ambient, and reflections by secondary rays weighted by Schlick
// Fresnel. Rough reflections average a few stratified rays whose jitter is a hash of the hit point
// quantised on its surface (primitive, face, 2 mm cells of the face coordinates), so the reflected
// content is a function of the scene and the view ray only, never of the pixel or the frame.
// Rows run in parallel with OpenMP; every pixel is a pure function of its inputs, so the output is
// bit-identical for any thread count.
#include "core/common/camera.h"
#include "core/common/image.h"
#include "core/synth/scene.h"

#include <Eigen/Geometry>

namespace rrg::synth {

struct RenderParams {
  int threads = 0;            // OpenMP threads; 0 = OpenMP's default
  int rough_samples = 3;      // jittered reflection rays on rough surfaces (first bounce)
  int max_bounces = 2;        // reflection depth; deeper bounces use one unjittered ray
  bool shadows = true;        // shadow rays from first-hit surfaces to each light
  float jitter_cell = 0.002f; // metres: surface quantisation of the roughness jitter hash
  // Depth on mirrors (first hit with F0 > mirror_f0) as a sensor that sees through the glass
  // reports it: the z-depth of the mirrored point (the first hit of the reflected ray, unfolded
  // behind the glass), 0 when the reflected ray leaves the scene. Colour and labels are unchanged.
  bool virtual_mirror_depth = false;
  float mirror_f0 = 0.5f;
};

struct RenderOutput {
  ColorImage color;          // display-ready RGB in [0,1] (tone-mapped, gamma 2.2)
  DepthImage depth;          // z-depth of the first hit along the optical axis, metres, 0 = none
                             // (of the mirrored point on mirrors with virtual_mirror_depth)
  LabelImage labels;         // semantic category of the first hit (Category), 0 = none
  LabelImage planes;         // plane id of the first hit, 0 = curved or none
  MaskImage reflective;      // 1 where the first hit has F0 > 0
  Image<uint16_t> material;  // material index + 1 of the first hit, 0 = none
};

// Renders one view of a finalized scene from pose T_wc (camera -> world).
// Throws std::invalid_argument on invalid intrinsics or an unfinalized scene.
RenderOutput render_view(const Scene& scene, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                         const RenderParams& params = {});

// Radiance (linear, before tone mapping) along one world ray, with the renderer's shading rules;
// bounce = 0 for a camera ray. Exposed for tests.
Color trace_radiance(const Scene& scene, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                     const RenderParams& params, int bounce = 0);

}  // namespace rrg::synth
