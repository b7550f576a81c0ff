#pragma once
// Plain view bundles the render stages take (internal): kernels see only these, never owners.
#include "core/common/span.h"
#include "core/render/splat.h"

#include <Eigen/Core>

#include <cstdint>
#include <limits>

namespace rrg::kernel {

struct GaussianViews {
  Span<const Eigen::Vector3f> means, log_scales;  // [N, 3]
  Span<const Eigen::Vector4f> quats;              // [N, 4]
  Span<const float> logit_opacities;              // [N]
  Span<const Eigen::Vector3f> sh;                 // [N, K, 3]
  Span<const int32_t> plane_ids;                  // [N]
};

struct GaussianGradViews {
  Span<Eigen::Vector3f> v_means, v_log_scales;  // [N, 3]
  Span<Eigen::Vector4f> v_quats;                // [N, 4]
  Span<float> v_logit_opacities;                // [N]
  Span<Eigen::Vector3f> v_sh;                   // [N, K, 3]
  Span<uint8_t> touched;                        // [N] 1 where a gradient above is non-zero
};

// Sorted tile lists: entries values[ranges[t].begin .. ranges[t].end) of tile t are Gaussian indices.
struct BinViews {
  Span<const int32_t> values;     // [M]
  Span<const TileRange> ranges;   // [tiles]
};

// Pass-3 plane handling of one rasterisation.
enum class PlaneMode : int32_t {
  Match,      // Gaussian i counts at u iff l_i == I(u) != 0 (grouped)
  All,        // no plane test (no grouping; one group of the multi-pass variant)
  PixelOnly,  // only pixels with I(u) == plane are processed, no per-Gaussian test (multi-pass backward)
};

struct BaseFwdArgs {
  View view;
  float eps;
  Span<const Splat> splats;                     // [N]
  BinViews bins;
  ImageView<const Eigen::Vector3f> C_t;
  ImageView<const float> D_t;
  ImageView<Eigen::Vector3f> C_g, C_b;
  ImageView<float> W_g, D_g, D_b;
};

struct BaseBwdArgs {
  View view;
  float eps;
  Span<const Splat> splats;
  BinViews bins;
  ImageView<const float> D_t, W_g, D_b;
  ImageView<const Eigen::Vector3f> C_b;
  ImageView<const Eigen::Vector3f> v_C_b;
  ImageView<const float> v_D_b;
  Span<SplatGrad> v_splats;                     // [N], accumulated (CUDA: atomically)
};

struct ReflFwdArgs {
  View view;
  Span<const Splat> splats;
  BinViews bins;
  Span<const int32_t> plane_ids;
  ImageView<const int32_t> I;
  PlaneMode mode;
  int32_t plane;                                // for PixelOnly
  ImageView<Eigen::Vector3f> C_r;
  ImageView<float> W_r;
  // A pixel stops once the mean RGB of its C_r exceeds this (refl_mean_above); +inf: never.
  float stop_mean = std::numeric_limits<float>::infinity();
};

struct ReflBwdArgs {
  View view;
  Span<const Splat> splats;
  BinViews bins;
  Span<const int32_t> plane_ids;
  ImageView<const int32_t> I;
  PlaneMode mode;
  int32_t plane;
  ImageView<const Eigen::Vector3f> C_r;
  ImageView<const float> W_r;
  ImageView<const Eigen::Vector3f> v_C_r;       // total upstream of C_r (R v_C + v_C_r)
  Span<SplatGrad> v_splats;
};

}  // namespace rrg::kernel
