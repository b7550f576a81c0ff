#pragma once
// The mapping losses of paper §4.2.2 on the device the images live on (CPU or CUDA, one source):
//   L = (1 − λ) L1(C, C_gt) + λ (1 − SSIM(C, C_gt))    λ = 0.2
//     + λ_d · L1(D_b, D_gt) over pixels with D_gt > 0   λ_d = 0.2
//     + λ_g · ‖Sobel(C_r)‖₁                            λ_g = 0.05
//     + λ_rb · mean(R · C_b)                            λ_rb = 0.3 (ours: the base under a reflection)
// Every term returns its (unweighted) value and, when given a gradient image, ADDS
// weight · ∂term/∂input to it, so the caller builds the renderer's upstream images term by term.
// Means are over pixels and channels (SSIM: 3DGS's window and constants, core/eval/image_metrics.h).
#include "core/common/buffer.h"

namespace rrg {

struct LossWeights {
  float lambda_ssim = 0.2f;    // λ of L_color
  float lambda_depth = 0.2f;   // λ_d
  float lambda_sobel = 0.05f;  // λ_g
  // λ_rb (ours, docs/mapping.md "The base under a reflection"): C = C_b + R·C_r sees only the sum
  // on a reflective pixel, and C_r ≥ 0 only adds light; this weight on the mean of R·C_b settles
  // the split toward a base that leaves the reflected light to C_r. 0 = the paper's loss.
  float lambda_reflective_base = 0.3f;
  void validate() const;       // throws std::invalid_argument naming the bad weight
};

struct LossValues {
  double l1 = 0, ssim = 0, depth_l1 = 0, sobel = 0, reflective_base = 0;
  double total = 0;  // (1 − λ) l1 + λ (1 − ssim) + λ_d depth_l1 + λ_g sobel + λ_rb reflective_base
};

// mean |x − y|; v_x += weight ∂/∂x.
float l1_loss(const DeviceImage<Color>& x, const DeviceImage<Color>& y, DeviceImage<Color>* v_x, float weight);
// mean SSIM(x, y) (y is the reference); v_x += weight ∂/∂x. scratch is resized as needed.
float ssim(const DeviceImage<Color>& x, const DeviceImage<Color>& y, DeviceImage<Color>* v_x, float weight,
           Buffer<float>& scratch);
// mean |d − d_gt| over d_gt > 0 (0 when none); v_d += weight ∂/∂d.
float depth_l1_loss(const DeviceImage<float>& d, const DeviceImage<float>& d_gt, DeviceImage<float>* v_d,
                    float weight);
// mean (|Gx| + |Gy|) of the Sobel responses over interior pixels; v_x += weight ∂/∂x. scratch (the
// responses' signs, for the gradient) is resized as needed; so is `values` on the CPU (each
// element's response, which the CPU's row pass reduces; kernel::sobel_l1_loss_rows).
float sobel_l1_loss(const DeviceImage<Color>& x, DeviceImage<Color>* v_x, float weight, Buffer<int8_t>& scratch,
                    Buffer<float>& values);

// mean over pixels and channels of R · C_b, R the reflection mask as 0 / 1 (other values break the
// split below). Its gradient weight · ∂/∂C_b goes into the renderer's upstream images as
// v_C += s R and v_C_r −= s R (s = weight / 3N): the renderer passes v_C to C_b and R v_C + v_C_r to
// C_r, so C_b gets s R and C_r nothing. v_C and v_C_r are both given or both null.
float reflective_base_prior(const DeviceImage<Color>& C_b, const DeviceImage<float>& R, DeviceImage<Color>* v_C,
                            DeviceImage<Color>* v_C_r, float weight);

// Working memory of mapping_loss, kept by the caller between calls.
struct LossScratch {
  Buffer<float> ssim;
  Buffer<int8_t> sobel;
  Buffer<float> sobel_values;  // CPU only
};

// The renderer's reflection-pass images the reflection terms read (λ_g, λ_rb).
struct ReflectionImages {
  const DeviceImage<Color>& C_r;
  const DeviceImage<Color>& C_b;
  const DeviceImage<float>& R;  // 0 / 1
};

// The whole mapping loss. Overwrites v_C, v_D_b (and v_C_r when refl is given and λ_g or λ_rb > 0;
// else it is left empty) with ∂L/∂C, ∂L/∂D_b, ∂L/∂C_r, allocated on the images' device. Without
// refl (no reflection pass) the reflection terms are 0.
LossValues mapping_loss(const DeviceImage<Color>& C, const DeviceImage<Color>& C_gt, const DeviceImage<float>& D_b,
                        const DeviceImage<float>& D_gt, const ReflectionImages* refl, const LossWeights& w,
                        DeviceImage<Color>& v_C, DeviceImage<float>& v_D_b, DeviceImage<Color>& v_C_r,
                        LossScratch& scratch);

}  // namespace rrg
