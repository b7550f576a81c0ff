#pragma once
// Inputs, outputs and parameters of the three-pass renderer (paper §3.2, DESIGN.md §1).
#include "core/common/buffer.h"
#include "core/common/camera.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <string>

namespace rrg {

// How pass 3 treats the reflection groups (the paper's ablation table).
enum class ReflectionVariant {
  Grouped,          // ours: all groups in one pass, Gaussian i counts at u only if l_i == I(u)
  NoPlaneGrouping,  // one reflection set, vanilla 3DGS compositing (no plane test)
  MultiPass,        // each group rendered alone over the image, composited with masks 1(I = k)
};
std::string to_string(ReflectionVariant v);        // "grouped", "no-grouping", "multi-pass"
ReflectionVariant parse_reflection_variant(const std::string& s);  // throws std::invalid_argument

struct RenderParams {
  float eps = 0.02f;            // epsilon of the depth cull d_i < D_t(u) + eps: TSDF truncation, 2 cm
  float near_plane = 0.05f;     // Gaussians with camera z below this are culled, metres
  float low_pass = 0.3f;        // added to the diagonal of the 2-D covariance, pixels^2 (3DGS)
  float max_radius_px = 256.f;  // cap on the screen radius 3 sqrt(lambda_max), pixels
  int sh_degree = 3;            // SH degree evaluated (each set's own degree if lower)
  ReflectionVariant variant = ReflectionVariant::Grouped;
  bool time_stages = false;     // synchronise after each stage and fill RenderTimings
};

// Pass 1 (TSDF raycast) results the Gaussian passes consume; all the same size, on one device.
struct RaycastInputs {
  DeviceImage<Color> C_t;    // TSDF colour
  DeviceImage<float> D_t;    // TSDF depth, metres; 0 = the ray missed
  DeviceImage<int32_t> I;    // plane id map; 0 = no plane
  DeviceImage<float> R;      // reflection mask R (R_raw > 0.5), 0 or 1
};

struct RenderOutputs {
  DeviceImage<Color> C;      // C = C_b + R C_r
  DeviceImage<Color> C_b;    // (C_t + C_g) / (1 + W_g)
  DeviceImage<Color> C_g;    // A_b[c]
  DeviceImage<Color> C_r;    // A_r[c]
  DeviceImage<float> D_b;    // (D_t + D_g) / (1 + W_g)
  DeviceImage<float> D_g;    // A_b[d]
  DeviceImage<float> W_g;    // A_b[1]
  DeviceImage<float> W_r;    // A_r[1]
};

// dL/d(outputs) for the backward pass. v_C_r is optional (empty = 0): it carries the gradient of
// terms on C_r itself (the Sobel regulariser); C's own gradient reaches C_r through R.
struct RenderUpstream {
  DeviceImage<Color> v_C;
  DeviceImage<float> v_D_b;
  DeviceImage<Color> v_C_r;
};

// Milliseconds of the last render()/backward() (filled when RenderParams::time_stages).
struct RenderTimings {
  double project_ms = 0;     // projection of both sets + tile binning of the base set
  double base_ms = 0;        // pass 2 rasterisation
  double reflection_ms = 0;  // pass 3: binning incl. the depth sort, rasterisation
  double composite_ms = 0;   // C = C_b + R C_r
  double backward_ms = 0;    // both passes, back to every Gaussian parameter
};

// The view: intrinsics and the pose T_wc (camera -> world, OpenCV axes).
struct RenderCamera {
  Intrinsics K;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
};

}  // namespace rrg
