#pragma once
// Plain per-Gaussian records passed between the render stages, templated on the scalar (float in
// the renderer, double in the finite-difference reference of the tests). Trivially copyable.
#include "core/common/hd.h"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace rrg::kernel {

template <class T> using Vec2 = Eigen::Matrix<T, 2, 1>;
template <class T> using Vec3 = Eigen::Matrix<T, 3, 1>;
template <class T> using Vec4 = Eigen::Matrix<T, 4, 1>;
template <class T> using Mat2 = Eigen::Matrix<T, 2, 2>;
template <class T> using Mat3 = Eigen::Matrix<T, 3, 3>;
template <class T> using Mat23 = Eigen::Matrix<T, 2, 3>;

// Scalar maths with the float overloads picked explicitly (no silent promotion on the host).
RRG_HD inline float k_exp(float x) { return expf(x); }
RRG_HD inline double k_exp(double x) { return exp(x); }
RRG_HD inline float k_log(float x) { return logf(x); }
RRG_HD inline double k_log(double x) { return log(x); }
RRG_HD inline float k_sqrt(float x) { return sqrtf(x); }
RRG_HD inline double k_sqrt(double x) { return sqrt(x); }
RRG_HD inline float k_ceil(float x) { return ceilf(x); }
RRG_HD inline double k_ceil(double x) { return ceil(x); }
RRG_HD inline float k_floor(float x) { return floorf(x); }
RRG_HD inline double k_floor(double x) { return floor(x); }

inline constexpr int kTileSize = 16;  // tile binning, 16 x 16 pixels

// A projected Gaussian (2-D splat): what a pixel needs. Gradients use the same record (v_*).
template <class T>
struct SplatT {
  T mean[2];   // p_hat, pixels
  T conic[3];  // Sigma'^-1 = [[a, b], [b, c]] as (a, b, c)
  T opacity;   // sigma = sigmoid(logit opacity)
  T color[3];  // c = max(SH(view dir) + 0.5, 0)
  T depth;     // d_i, camera z of the mean, metres
};
using Splat = SplatT<float>;
using SplatGrad = SplatT<float>;

// Tiles [x0, x1) x [y0, y1) a splat touches; empty when culled.
struct TileRect {
  int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  RRG_HD int32_t count() const { return x1 > x0 && y1 > y0 ? (x1 - x0) * (y1 - y0) : 0; }
};

// [begin, end) of a tile's entries in the sorted binning arrays.
struct TileRange {
  int32_t begin = 0, end = 0;
};

// The pinhole view the Gaussians are rendered from: world -> camera rotation/translation (row-major
// R_cw), camera centre in world, intrinsics, and the projection parameters.
template <class T>
struct ViewT {
  T R_cw[9];
  T t_cw[3];
  T center_w[3];
  T fx, fy, cx, cy;
  int32_t width, height;
  T near_plane;  // z below this is culled, metres
  T low_pass;    // added to the diagonal of Sigma' (pixels^2), 3DGS's 0.3
  T max_radius;  // screen-radius cap, pixels
  int32_t sh_degree;  // degree evaluated (<= the set's)
  int32_t sh_stride;  // coefficients stored per Gaussian

  RRG_HD RRG_INLINE Mat3<T> R() const {
    Mat3<T> m;
    m << R_cw[0], R_cw[1], R_cw[2], R_cw[3], R_cw[4], R_cw[5], R_cw[6], R_cw[7], R_cw[8];
    return m;
  }
  RRG_HD RRG_INLINE Vec3<T> t() const { return {t_cw[0], t_cw[1], t_cw[2]}; }
  RRG_HD RRG_INLINE Vec3<T> center() const { return {center_w[0], center_w[1], center_w[2]}; }
  RRG_HD int tiles_x() const { return (width + kTileSize - 1) / kTileSize; }
  RRG_HD int tiles_y() const { return (height + kTileSize - 1) / kTileSize; }
};
using View = ViewT<float>;

}  // namespace rrg::kernel
