#pragma once
// The reflection-aware Gaussian renderer, passes 2 and 3 of paper §3.2 with their backward passes,
// on the device the data lives on (CPU or CUDA, same source):
//   pass 2  C_g, W_g, D_g = A_b[c], A_b[1], A_b[d]   (sort-free, depth cull d_i < D_t(u) + eps)
//           C_b = (C_t + C_g) / (1 + W_g),  D_b = (D_t + D_g) / (1 + W_g)
//   pass 3  C_r, W_r = A_r[c], A_r[1]                (per-tile depth sort, alpha compositing,
//                                                     Gaussian i only where l_i == I(u))
//           C = C_b + R C_r
// Where the raycast missed (D_t = 0) there is no depth cull and no TSDF term:
// C_b = C_g / max(1, W_g), D_b = D_g / max(1, W_g) (docs/render.md).
// The renderer owns all scratch memory and reuses it across frames.
#include "core/gaussians/gaussian_grads.h"
#include "core/gaussians/gaussian_set.h"
#include "core/render/rasterize_cpu_scratch.h"
#include "core/render/render_types.h"
#include "core/render/splat.h"
#include "core/render/tile_bins.h"

#include <limits>
#include <span>
#include <vector>

namespace rrg {

// The sorted distinct non-zero plane ids l (the reflection groups) among plane_ids, or of a set's
// Gaussians (copied to the host).
std::vector<int32_t> distinct_planes(std::span<const int32_t> plane_ids);
std::vector<int32_t> distinct_planes(const GaussianSet& set);
// Whether pass 3 in its grouped form (a Gaussian reaches pixel u only when its plane id l equals
// I(u) != 0) can draw anything over plane-id map I for Gaussians on `planes` (sorted): some pixel's
// I(u) is one of them. When not, C_r = 0 and W_r = 0 everywhere and no reflection Gaussian gets a
// gradient, so the pass can be skipped with identical results.
bool shows_any_plane(const Image<int32_t>& I, std::span<const int32_t> planes);

class Renderer {
 public:
  explicit Renderer(const Device& device, RenderParams params = {});

  const Device& device() const { return device_; }
  const RenderParams& params() const { return params_; }
  void set_params(const RenderParams& params);

  // Renders base set G_b and reflection set G_r (both on device()) over the raycast inputs into
  // out (resized as needed). Keeps references to camera, sets and inputs for backward(): they must
  // stay alive and unchanged until then. Throws std::invalid_argument on mismatched sizes/devices.
  void render(const RenderCamera& camera, const GaussianSet& base, const GaussianSet& reflection,
              const RaycastInputs& raycast, RenderOutputs& out);

  // Pass 3 alone: C_r and W_r of `reflection` over the plane-id map I (the other outputs are left
  // as they are). What the tracking mask needs, C_r at a pose, without pass 2 or the TSDF colour.
  // backward() cannot follow it (it throws until the next render()). With a finite stop_mean a
  // pixel stops compositing once the mean RGB of its C_r exceeds stop_mean: C_r and W_r are exact
  // where that mean stays <= stop_mean, and elsewhere partial sums whose mean is > stop_mean (C_r
  // only grows along the list), which is all the mask's test mean > threshold needs.
  void render_reflection(const RenderCamera& camera, const GaussianSet& reflection, const DeviceImage<int32_t>& I,
                         RenderOutputs& out, float stop_mean = std::numeric_limits<float>::infinity());

  // Gradients of every parameter of both sets (not the TSDF maps) for the last render(), given
  // dL/dC, dL/dD_b and optionally dL/dC_r. Writes `touched` of v_base and v_reflection, and their
  // v_* entries where touched = 1; where it is 0 the gradient is zero and the entries keep whatever
  // they held (GaussianGrads).
  void backward(const RenderUpstream& upstream, GaussianGrads& v_base, GaussianGrads& v_reflection);

  const RenderTimings& timings() const { return timings_; }
  // Entries (tile, Gaussian) binned in the last render: base set, reflection set (summed over groups).
  int64_t base_entries() const { return base_entries_; }
  int64_t reflection_entries() const { return refl_entries_; }

 private:
  struct Projected {
    Buffer<kernel::Splat> splats;
    Buffer<kernel::TileRect> rects;
    Buffer<kernel::SplatGrad> v_splats;
    TileBins bins;
    kernel::CpuRasterScratch cpu;  // the CPU schedule's scratch (rasterize_cpu_scratch.h)
  };
  kernel::View make_view(const RenderCamera& camera, const GaussianSet& set) const;
  void project(const kernel::View& view, const GaussianSet& set, Projected& p);
  void reflection_forward(const kernel::View& view, const DeviceImage<int32_t>& I, RenderOutputs& out,
                          float stop_mean = std::numeric_limits<float>::infinity());
  void reflection_backward(const kernel::View& view, const DeviceImage<Color>& v_C_r);
  std::vector<int32_t> reflection_groups() const;

  Device device_;
  RenderParams params_;
  RenderTimings timings_;
  Projected base_, refl_;
  int64_t base_entries_ = 0, refl_entries_ = 0;
  // state of the last render, for backward()
  RenderCamera camera_;
  const GaussianSet* base_set_ = nullptr;
  const GaussianSet* refl_set_ = nullptr;
  const RaycastInputs* raycast_ = nullptr;
  const RenderOutputs* out_ = nullptr;
  // multi-pass scratch images and the combined upstream of C_r
  DeviceImage<Color> group_C_, v_C_r_;
  DeviceImage<float> group_W_;
};

}  // namespace rrg
