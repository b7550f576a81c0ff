#pragma once
// Per-pixel math of frame-to-model point-to-plane ICP (paper §4.1.2, stage 1), shared by both back
// ends: the only copy. The reduction struct holds the upper triangle of JᵀWJ, JᵀWr and statistics.
#include "core/common/camera.h"
#include "core/common/depth_noise_model.h"
#include "core/common/hd.h"
#include "core/common/span.h"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross()

namespace rrg::kernel {

// Σ over inlier pixels of the normal equations (21 + 6 values) and of r², plus counts.
struct IcpSystem {
  double jtj[21];    // upper triangle of Σ w JᵀJ, row-major
  double jtr[6];     // Σ w Jᵀ r
  double r2;         // Σ r² (unweighted, for the RMSE)
  double r2_ref;     // Σ (r s)², s = σ_n(z_ref) / σ_n(z) (1 without noise weighting): the residuals'
                     // scale in the units the weights of JᵀWJ assume
  double inliers;    // pixels that passed association and rejection
  double valid;      // source pixels with a vertex and a normal
  double agree;      // associated pixels within max_distance whose |r| <= max(δ, k σ_n(z)), whatever
                     // their normals (the tracking state's measure, IcpParams::min_agreement)
};

struct IcpSystemSum {
  RRG_HD IcpSystem operator()(const IcpSystem& a, const IcpSystem& b) const {
    IcpSystem s;
    for (int k = 0; k < 21; ++k) s.jtj[k] = a.jtj[k] + b.jtj[k];
    for (int k = 0; k < 6; ++k) s.jtr[k] = a.jtr[k] + b.jtr[k];
    s.r2 = a.r2 + b.r2;
    s.r2_ref = a.r2_ref + b.r2_ref;
    s.inliers = a.inliers + b.inliers;
    s.valid = a.valid + b.valid;
    s.agree = a.agree + b.agree;
    return s;
  }
};

RRG_HD inline IcpSystem icp_system_zero() {
  IcpSystem s;
  for (int k = 0; k < 21; ++k) s.jtj[k] = 0.0;
  for (int k = 0; k < 6; ++k) s.jtr[k] = 0.0;
  s.r2 = s.r2_ref = s.inliers = s.valid = s.agree = 0.0;
  return s;
}

// Everything one pixel needs: the source level (camera frame), the model raycast (world frame) and
// its camera, the current estimate T_wc and the rejection thresholds.
struct IcpArgs {
  ImageView<const Eigen::Vector3f> src_vertices;   // V_k^l at this level
  ImageView<const Eigen::Vector3f> src_normals;    // N_k^l
  ImageView<const Eigen::Vector3f> model_vertices; // V*_{k-1}^g
  ImageView<const Eigen::Vector3f> model_normals;  // N*_{k-1}^g
  Intrinsics K_model;
  Eigen::Matrix3f R_ref_cw;  // world -> model camera
  Eigen::Vector3f t_ref_cw;
  Eigen::Matrix3f R_wc;      // current estimate T_g,k
  Eigen::Vector3f t_wc;
  float max_distance, min_cos, huber_delta;
  // Noise weighting (IcpParams::noise_weighting): σ_n(z) of the sensor at the source point's depth
  // z, and σ_n at the reference depth; off when sigma_ref = 0.
  DepthNoiseModel noise;
  float sigma_ref = 0.0f;
  // σ_m² of the model surface (IcpParams::model_sigma_m), added to σ_n(z)² (sigma_ref includes it)
  float model_variance = 0.0f;
  // A pair agrees with the model when |r| <= max(huber_delta, agree_sigmas σ_n(z)) (`noise` is the
  // sensor's model with or without weighting).
  float agree_sigmas = 3.0f;
};

// Rounded single-precision multiply and add that the compiler may not fuse into an FMA. The
// association chain below (two rigid transforms and the projection) is written with them in a
// fixed order, so the host (x86-64 without FMA contraction) and CUDA (which contracts a*b+c into
// fma by default) compute bit-identical û: a pixel projecting within an ulp of a half-pixel
// position must pick the same model pixel on every back end. This matters at pyramid levels
// l >= 1, whose pixel centres map exactly onto half-pixel positions of the full-resolution model
// (c_l = (c + 0.5) / 2^l - 0.5), so small motions put many û next to a rounding tie.
RRG_HD inline float mul_rn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fmul_rn(a, b);
#else
  return a * b;
#endif
}
RRG_HD inline float add_rn(float a, float b) {
#if defined(__CUDA_ARCH__)
  return __fadd_rn(a, b);
#else
  return a + b;
#endif
}

// R x + t, each row summed left to right with rounded products: ((R0 x0 + R1 x1) + R2 x2) + t.
RRG_HD inline Eigen::Vector3f rigid_rn(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const Eigen::Vector3f& x) {
  Eigen::Vector3f out;
  for (int r = 0; r < 3; ++r)
    out[r] = add_rn(add_rn(add_rn(mul_rn(R(r, 0), x.x()), mul_rn(R(r, 1), x.y())), mul_rn(R(r, 2), x.z())), t[r]);
  return out;
}

// û = round(proj(K p)) with round(x) = floor(x + 0.5), from rounded operations only.
RRG_HD inline void project_round(const Intrinsics& K, const Eigen::Vector3f& p, int& ux, int& uy) {
  const float u = add_rn(mul_rn(K.fx, p.x()) / p.z(), K.cx), v = add_rn(mul_rn(K.fy, p.y()) / p.z(), K.cy);
  ux = int(floorf(add_rn(u, 0.5f)));
  uy = int(floorf(add_rn(v, 0.5f)));
}

// One pixel u: p = T_g,k V_k^l(u); û = proj(K T_ref⁻¹ p); pair with (q, m) = (V*(û), N*(û)) unless
// |p − q| > max_distance or ∠(R N_k^l(u), m) exceeds the angle. Residual r = (p − q)·m, Jacobian
// for the left update T ← exp(ξ) T, ξ = [ρ; φ]:  J = [mᵀ, (p × m)ᵀ]. With noise weighting the
// residual is scaled to the reference noise, r̃ = r s with s = σ_ref / σ_n(z), and the weight is
// w = s² min(1, δ/|r̃|) (Huber on r̃); without it s = 1. Before the normal test, a pair whose
// |r| <= max(δ, k σ_n(z)) counts as agreeing with the model (the quality measure).
// Adds the pixel's share to s (the valid count, and the normal equations when it is an inlier);
// accumulating in place keeps the CPU loop free of a 30-double temporary per pixel.
RRG_HD inline void icp_accumulate(const IcpArgs& a, int64_t i, IcpSystem& s) {
  const Eigen::Vector3f v = a.src_vertices[i];
  const Eigen::Vector3f n = a.src_normals[i];
  if (!(v.z() > 0.0f) || n.squaredNorm() < 0.5f) return;
  s.valid += 1.0;
  const Eigen::Vector3f p = rigid_rn(a.R_wc, a.t_wc, v);
  const Eigen::Vector3f p_ref = rigid_rn(a.R_ref_cw, a.t_ref_cw, p);
  if (!(p_ref.z() > 0.0f)) return;
  int ux, uy;
  project_round(a.K_model, p_ref, ux, uy);
  if (!a.model_vertices.contains(ux, uy)) return;
  const Eigen::Vector3f m = a.model_normals(ux, uy);
  if (m.squaredNorm() < 0.5f) return;
  const Eigen::Vector3f q = a.model_vertices(ux, uy);
  const Eigen::Vector3f d = p - q;
  if (d.squaredNorm() > a.max_distance * a.max_distance) return;
  const float r = d.dot(m);
  const float sigma = a.noise.sigma(v.z());
  if (fabsf(r) <= fmaxf(a.huber_delta, a.agree_sigmas * sigma)) s.agree += 1.0;
  if ((a.R_wc * n).dot(m) < a.min_cos) return;
  float scale = 1.0f;  // s = σ_ref / σ_n(z), or with a model term σ_ref / sqrt(σ_n(z)² + σ_m²)
  if (a.sigma_ref > 0.0f) {
    scale = a.model_variance > 0.0f ? a.sigma_ref / sqrtf(sigma * sigma + a.model_variance) : a.sigma_ref / sigma;
  }
  const float r_ref = r * scale;
  const float w = scale * scale * (fabsf(r_ref) <= a.huber_delta ? 1.0f : a.huber_delta / fabsf(r_ref));
  const Eigen::Vector3f pm = p.cross(m);
  const float J[6] = {m.x(), m.y(), m.z(), pm.x(), pm.y(), pm.z()};
  int k = 0;
  for (int row = 0; row < 6; ++row) {
    const float wj = w * J[row];
    for (int col = row; col < 6; ++col) s.jtj[k++] += double(wj * J[col]);
    s.jtr[row] += double(wj * r);
  }
  s.r2 += double(r) * double(r);
  s.r2_ref += double(r_ref) * double(r_ref);
  s.inliers += 1.0;
}

// Pixel i alone (the CUDA reduction's per-element map).
RRG_HD inline IcpSystem icp_pixel(const IcpArgs& a, int64_t i) {
  IcpSystem s = icp_system_zero();
  icp_accumulate(a, i, s);
  return s;
}

}  // namespace rrg::kernel
