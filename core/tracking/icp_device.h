#pragma once
// Per-pixel math of frame-to-model point-to-plane ICP (paper §4.1.2, stage 1), shared by both back
// ends: the only copy. The reduction struct holds the upper triangle of JᵀWJ, JᵀWr and statistics.
#include "core/common/camera.h"
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
  double inliers;    // pixels that passed association and rejection
  double valid;      // source pixels with a vertex and a normal
};

struct IcpSystemSum {
  RRG_HD IcpSystem operator()(const IcpSystem& a, const IcpSystem& b) const {
    IcpSystem s;
    for (int k = 0; k < 21; ++k) s.jtj[k] = a.jtj[k] + b.jtj[k];
    for (int k = 0; k < 6; ++k) s.jtr[k] = a.jtr[k] + b.jtr[k];
    s.r2 = a.r2 + b.r2;
    s.inliers = a.inliers + b.inliers;
    s.valid = a.valid + b.valid;
    return s;
  }
};

RRG_HD inline IcpSystem icp_system_zero() {
  IcpSystem s;
  for (int k = 0; k < 21; ++k) s.jtj[k] = 0.0;
  for (int k = 0; k < 6; ++k) s.jtr[k] = 0.0;
  s.r2 = s.inliers = s.valid = 0.0;
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
};

// One pixel u: p = T_g,k V_k^l(u); û = proj(K T_ref⁻¹ p); pair with (q, m) = (V*(û), N*(û)) unless
// |p − q| > max_distance or ∠(R N_k^l(u), m) exceeds the angle. Residual r = (p − q)·m, Jacobian
// for the left update T ← exp(ξ) T, ξ = [ρ; φ]:  J = [mᵀ, (p × m)ᵀ]; Huber weight w = min(1, δ/|r|).
RRG_HD inline IcpSystem icp_pixel(const IcpArgs& a, int64_t i) {
  IcpSystem s = icp_system_zero();
  const Eigen::Vector3f v = a.src_vertices[i];
  const Eigen::Vector3f n = a.src_normals[i];
  if (!(v.z() > 0.0f) || n.squaredNorm() < 0.5f) return s;
  s.valid = 1.0;
  const Eigen::Vector3f p = a.R_wc * v + a.t_wc;
  const Eigen::Vector3f p_ref = a.R_ref_cw * p + a.t_ref_cw;
  if (!(p_ref.z() > 0.0f)) return s;
  const Eigen::Vector2f uv = a.K_model.project(p_ref);
  const int ux = int(floorf(uv.x() + 0.5f)), uy = int(floorf(uv.y() + 0.5f));
  if (!a.model_vertices.contains(ux, uy)) return s;
  const Eigen::Vector3f m = a.model_normals(ux, uy);
  if (m.squaredNorm() < 0.5f) return s;
  const Eigen::Vector3f q = a.model_vertices(ux, uy);
  const Eigen::Vector3f d = p - q;
  if (d.squaredNorm() > a.max_distance * a.max_distance) return s;
  if ((a.R_wc * n).dot(m) < a.min_cos) return s;
  const float r = d.dot(m);
  const float w = fabsf(r) <= a.huber_delta ? 1.0f : a.huber_delta / fabsf(r);
  const Eigen::Vector3f pm = p.cross(m);
  const float J[6] = {m.x(), m.y(), m.z(), pm.x(), pm.y(), pm.z()};
  int k = 0;
  for (int row = 0; row < 6; ++row) {
    for (int col = row; col < 6; ++col) s.jtj[k++] = double(w * J[row] * J[col]);
    s.jtr[row] = double(w * J[row] * r);
  }
  s.r2 = double(r) * double(r);
  s.inliers = 1.0;
  return s;
}

}  // namespace rrg::kernel
