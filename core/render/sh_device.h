#pragma once
// View-dependent colour from spherical harmonics, 3DGS basis and constants, degrees 0-3:
// c = max(sum_k b_k(d) SH_k + 0.5, 0), d the unit direction from the camera centre to the mean.
// Forward and backward, the only copy.
#include "core/common/hd.h"
#include "core/render/splat.h"

namespace rrg::kernel {

inline constexpr int kMaxShCoeffs = 16;

// b[k] for k < (degree+1)^2 at the unit direction d; db[k] = grad_d b_k when db is not null.
template <class T>
RRG_HD RRG_INLINE void sh_basis(int degree, const Vec3<T>& d, T* b, Vec3<T>* db) {
  constexpr double C0 = 0.28209479177387814, C1 = 0.4886025119029199;
  constexpr double C2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                            -1.0925484305920792, 0.5462742152960396};
  constexpr double C3[7] = {-0.5900435899266435, 2.890611442640554, -0.4570457994644658,
                            0.3731763325901154,  -0.4570457994644658, 1.445305721320277,
                            -0.5900435899266435};
  const T x = d.x(), y = d.y(), z = d.z();
  b[0] = T(C0);
  if (db) db[0] = Vec3<T>::Zero();
  if (degree < 1) return;
  b[1] = T(-C1) * y;
  b[2] = T(C1) * z;
  b[3] = T(-C1) * x;
  if (db) {
    db[1] = {T(0), T(-C1), T(0)};
    db[2] = {T(0), T(0), T(C1)};
    db[3] = {T(-C1), T(0), T(0)};
  }
  if (degree < 2) return;
  const T xx = x * x, yy = y * y, zz = z * z;
  b[4] = T(C2[0]) * x * y;
  b[5] = T(C2[1]) * y * z;
  b[6] = T(C2[2]) * (2 * zz - xx - yy);
  b[7] = T(C2[3]) * x * z;
  b[8] = T(C2[4]) * (xx - yy);
  if (db) {
    db[4] = T(C2[0]) * Vec3<T>(y, x, 0);
    db[5] = T(C2[1]) * Vec3<T>(0, z, y);
    db[6] = T(C2[2]) * Vec3<T>(-2 * x, -2 * y, 4 * z);
    db[7] = T(C2[3]) * Vec3<T>(z, 0, x);
    db[8] = T(C2[4]) * Vec3<T>(2 * x, -2 * y, 0);
  }
  if (degree < 3) return;
  b[9] = T(C3[0]) * y * (3 * xx - yy);
  b[10] = T(C3[1]) * x * y * z;
  b[11] = T(C3[2]) * y * (4 * zz - xx - yy);
  b[12] = T(C3[3]) * z * (2 * zz - 3 * xx - 3 * yy);
  b[13] = T(C3[4]) * x * (4 * zz - xx - yy);
  b[14] = T(C3[5]) * z * (xx - yy);
  b[15] = T(C3[6]) * x * (xx - 3 * yy);
  if (db) {
    db[9] = T(C3[0]) * Vec3<T>(6 * x * y, 3 * xx - 3 * yy, 0);
    db[10] = T(C3[1]) * Vec3<T>(y * z, x * z, x * y);
    db[11] = T(C3[2]) * Vec3<T>(-2 * x * y, 4 * zz - xx - 3 * yy, 8 * y * z);
    db[12] = T(C3[3]) * Vec3<T>(-6 * x * z, -6 * y * z, 6 * zz - 3 * xx - 3 * yy);
    db[13] = T(C3[4]) * Vec3<T>(4 * zz - 3 * xx - yy, -2 * x * y, 8 * x * z);
    db[14] = T(C3[5]) * Vec3<T>(2 * x * z, -2 * y * z, xx - yy);
    db[15] = T(C3[6]) * Vec3<T>(3 * xx - 3 * yy, -6 * x * y, 0);
  }
}

// The coefficients of one Gaussian: sh[k] of the storage's [K, 3] rows (a pointer), or one lane of a
// block of L Gaussians copied lane-major (LaneSh: channel c of coefficient k at p[(3 k + c) L], p at
// the lane's first element), which the CPU projection reads in its vector loop (project_cpu.cpp).
template <int L>
struct LaneSh {
  const float* p;
};

template <class T, class V>
RRG_HD RRG_INLINE Vec3<T> sh_coeff(const V* sh, int k) {
  return sh[k].template cast<T>();
}

template <class T, int L>
RRG_HD RRG_INLINE Vec3<T> sh_coeff(LaneSh<L> sh, int k) {
  return {T(sh.p[(3 * k) * L]), T(sh.p[(3 * k + 1) * L]), T(sh.p[(3 * k + 2) * L])};
}

// raw = sum_k b_k SH_k + 0.5 (unrolled: with a constant degree the CPU vector loop needs no inner loop).
template <class T, class Sh>
RRG_HD RRG_INLINE Vec3<T> sh_raw(int degree, Sh sh, const T* b) {
  Vec3<T> raw(T(0.5), T(0.5), T(0.5));
  RRG_UNROLL
  for (int k = 0; k < (degree + 1) * (degree + 1); ++k) raw += b[k] * sh_coeff<T>(sh, k);
  return raw;
}

// c = max(sum_k b_k(dir(p)) SH_k + 0.5, 0), dir(p) = (p - o) / |p - o|, o the camera centre (p = o
// gives NaN: such a mean is behind the near plane and culled).
template <class T, class Sh>
RRG_HD RRG_INLINE Vec3<T> sh_color(int degree, Sh sh, const Vec3<T>& mean, const Vec3<T>& center) {
  const Vec3<T> v = mean - center;
  const Vec3<T> d = v / k_sqrt(v.squaredNorm());
  T b[kMaxShCoeffs];
  sh_basis<T>(degree, d, b, nullptr);
  return sh_raw<T>(degree, sh, b).cwiseMax(T(0));
}

// Where the backward adds the coefficients' gradients: rows of [K, 3] (a pointer), or one lane of
// a lane-major block (LaneShGrad, the layout of LaneSh).
template <int L>
struct LaneShGrad {
  float* p;
};

template <class T, class V>
RRG_HD RRG_INLINE void sh_grad_add(V* v_sh, int k, const Vec3<T>& g) {
  v_sh[k] += g;
}

template <class T, int L>
RRG_HD RRG_INLINE void sh_grad_add(LaneShGrad<L> v_sh, int k, const Vec3<T>& g) {
  for (int c = 0; c < 3; ++c) v_sh.p[(3 * k + c) * L] += g[c];
}

// Backward of sh_color: v_sh[k] += b_k * v_raw (channels clamped at 0 pass no gradient); returns
// the gradient w.r.t. the mean through the view direction.
template <class T, class Sh, class VSh>
RRG_TU_LOCAL RRG_HD RRG_INLINE Vec3<T> sh_color_bwd(int degree, Sh sh, const Vec3<T>& mean, const Vec3<T>& center,
                                                    const Vec3<T>& v_color, VSh v_sh) {
  const Vec3<T> v = mean - center;
  const T len = k_sqrt(v.squaredNorm());
  const Vec3<T> d = v / len;
  T b[kMaxShCoeffs];
  Vec3<T> db[kMaxShCoeffs];
  for (int k = 0; k < kMaxShCoeffs; ++k) db[k].setZero();  // (only the first K are read; GCC cannot tell)
  sh_basis<T>(degree, d, b, db);
  const Vec3<T> raw = sh_raw<T>(degree, sh, b);
  Vec3<T> v_raw;
  for (int ch = 0; ch < 3; ++ch) v_raw[ch] = raw[ch] < T(0) ? T(0) : v_color[ch];
  Vec3<T> v_d = Vec3<T>::Zero();
  RRG_UNROLL
  for (int k = 0; k < (degree + 1) * (degree + 1); ++k) {
    sh_grad_add<T>(v_sh, k, Vec3<T>(b[k] * v_raw));
    v_d += sh_coeff<T>(sh, k).dot(v_raw) * db[k];
  }
  // d = v / |v|: v_v = (v_d - d (d . v_d)) / |v|
  return (v_d - d * d.dot(v_d)) / len;
}

}  // namespace rrg::kernel
