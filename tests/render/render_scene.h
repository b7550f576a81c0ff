#pragma once
// Test scenes for the renderer: random Gaussian sets and synthetic raycast inputs (pass 1 is
// another module's; these stand in for it), and a brute-force double-precision reference of
// passes 2 and 3 built on the same per-element functions (core/render/*_device.h) but with none
// of the tiling/sorting machinery, for forward checks and finite differences.
#include "core/common/image.h"
#include "core/gaussians/gaussian_set.h"
#include "core/render/render_types.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rrg::test {

struct HostRaycast {
  ColorImage C_t;
  DepthImage D_t;
  Image<int32_t> I;
  Image<float> R;
};
RaycastInputs to_device(const HostRaycast& h, const Device& device);

// n Gaussians in front of the identity camera at depths [z0, z1], screen radii of a few pixels at
// focal length f, random rotations/opacities, SH of the given degree, plane ids drawn from planes
// (empty: all 0).
GaussianHost random_gaussians(int n, int sh_degree, float z0, float z1, float f, const std::vector<int32_t>& planes,
                              uint32_t seed);
// A small scene: 32x24 camera (slightly rotated, translated), a tilted TSDF surface with a missed
// corner, planes 1 and 2 plus a no-plane band, R = 1 except a band; inputs in [0,1].
struct SmallScene {
  RenderCamera camera;
  HostRaycast raycast;
  GaussianHost base, refl;
};
SmallScene small_scene(uint32_t seed, int w = 32, int h = 24);

// Upstream gradients with random entries (seeded), same size as the camera.
struct HostUpstream {
  ColorImage v_C, v_C_r;
  DepthImage v_D_b;
};
HostUpstream random_upstream(int w, int h, uint32_t seed);
RenderUpstream to_device(const HostUpstream& u, const Device& device);

// ---- double-precision reference ---------------------------------------------------------------
struct GaussiansD {  // parameters in double, as the finite differences perturb them
  int sh_degree = 0;
  std::vector<Eigen::Vector3d> means, log_scales, sh;
  std::vector<Eigen::Vector4d> quats;
  std::vector<double> logit_opacities;
  std::vector<int32_t> plane_ids;
  static GaussiansD from(const GaussianHost& h);
};
struct ReferenceOutputs {
  std::vector<Eigen::Vector3d> C, C_b, C_r;
  std::vector<double> D_b, W_g, W_r;
};
ReferenceOutputs render_reference(const RenderCamera& camera, const GaussiansD& base, const GaussiansD& refl,
                                  const HostRaycast& in, const RenderParams& params);
// L = sum_u v_C . C + v_D_b D_b + v_C_r . C_r
double reference_loss(const ReferenceOutputs& out, const HostUpstream& up);

}  // namespace rrg::test
