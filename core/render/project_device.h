#pragma once
// One Gaussian -> one splat (EWA splatting, Zwicker et al.; 3DGS): forward and backward, the only
// copy of the math. p_c = R_cw p + t_cw; Sigma = R S S^T R^T with S = diag(exp(log s)) and R from
// the normalised quaternion; Sigma' = J R_cw Sigma R_cw^T J^T + low_pass I (J the projection's
// Jacobian at p_c, its x/z and y/z clamped to 1.3 x the half field of view as in 3DGS);
// p_hat = (fx x/z + cx, fy y/z + cy); screen radius ceil(3 sqrt(lambda_max(Sigma'))) capped.
#include "core/render/sh_device.h"
#include "core/render/splat.h"

#include <cmath>

namespace rrg::kernel {

// The parameters of one Gaussian, read from a GaussianSet (S is the storage's SH vector type).
template <class T, class S>
struct GaussianInT {
  Vec3<T> mean, log_scale;
  Vec4<T> quat;  // w, x, y, z; normalised here
  T logit_opacity;
  const S* sh;  // [K, 3]
};

template <class T>
RRG_HD inline T sigmoid(T x) {
  return T(1) / (T(1) + k_exp(-x));
}

// Rotation of the unit quaternion q = (w, x, y, z).
template <class T>
RRG_HD inline Mat3<T> quat_to_rot(const Vec4<T>& q) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  Mat3<T> R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

// Gradient w.r.t. the unit quaternion q of <v_R, R(q)>.
template <class T>
RRG_HD inline Vec4<T> quat_to_rot_bwd(const Vec4<T>& q, const Mat3<T>& g) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  return Vec4<T>(2 * (-z * g(0, 1) + y * g(0, 2) + z * g(1, 0) - x * g(1, 2) - y * g(2, 0) + x * g(2, 1)),
                 2 * (y * g(0, 1) + z * g(0, 2) + y * g(1, 0) - 2 * x * g(1, 1) - w * g(1, 2) + z * g(2, 0) +
                      w * g(2, 1) - 2 * x * g(2, 2)),
                 2 * (-2 * y * g(0, 0) + x * g(0, 1) + w * g(0, 2) + x * g(1, 0) + z * g(1, 2) - w * g(2, 0) +
                      z * g(2, 1) - 2 * y * g(2, 2)),
                 2 * (-2 * z * g(0, 0) - w * g(0, 1) + x * g(0, 2) + w * g(1, 0) - 2 * z * g(1, 1) + y * g(1, 2) +
                      x * g(2, 0) + y * g(2, 1)));
}

// Intermediate quantities of the projection, shared by forward and backward.
template <class T>
struct ProjectionT {
  Vec3<T> p_c;        // mean in the camera frame
  Vec3<T> t;          // p_c with x/z, y/z clamped (J is evaluated there)
  bool clamp_x, clamp_y;
  Mat23<T> J;
  Mat3<T> M;          // R S
  Vec3<T> s;          // exp(log s)
  Vec4<T> q;          // normalised quaternion
  Mat3<T> Sigma_c;    // covariance in the camera frame
  T A, B, C;          // Sigma' entries (low-pass included)
  T det;
};

// Fills pr; false when the Gaussian is culled (behind the near plane, or degenerate Sigma').
template <class T, class S>
RRG_TU_LOCAL RRG_HD inline bool projection_terms(const ViewT<T>& v, const GaussianInT<T, S>& g, ProjectionT<T>& pr) {
  const Mat3<T> W = v.R();
  pr.p_c = W * g.mean + v.t();
  const T z = pr.p_c.z();
  if (!(z >= v.near_plane)) return false;
  const T lim_x = T(1.3) * T(0.5) * T(v.width) / v.fx, lim_y = T(1.3) * T(0.5) * T(v.height) / v.fy;
  const T u = pr.p_c.x() / z, w = pr.p_c.y() / z;
  pr.clamp_x = u < -lim_x || u > lim_x;
  pr.clamp_y = w < -lim_y || w > lim_y;
  pr.t = {(pr.clamp_x ? (u < 0 ? -lim_x : lim_x) : u) * z, (pr.clamp_y ? (w < 0 ? -lim_y : lim_y) : w) * z, z};
  pr.J << v.fx / z, T(0), -v.fx * pr.t.x() / (z * z),  //
      T(0), v.fy / z, -v.fy * pr.t.y() / (z * z);
  const T qn = g.quat.norm();
  if (!(qn > T(0))) return false;
  pr.q = g.quat / qn;
  pr.s = {k_exp(g.log_scale.x()), k_exp(g.log_scale.y()), k_exp(g.log_scale.z())};
  pr.M = quat_to_rot(pr.q) * pr.s.asDiagonal();
  pr.Sigma_c = W * (pr.M * pr.M.transpose()) * W.transpose();
  const Mat2<T> S2 = pr.J * pr.Sigma_c * pr.J.transpose();
  pr.A = S2(0, 0) + v.low_pass;
  pr.B = S2(0, 1);
  pr.C = S2(1, 1) + v.low_pass;
  pr.det = pr.A * pr.C - pr.B * pr.B;
  return pr.det > T(0);
}

// Tiles touched by a splat of the given radius around p_hat (pixel centres at integer coordinates).
template <class T>
RRG_HD inline TileRect tile_rect(const ViewT<T>& v, const SplatT<T>& s, T radius) {
  auto clampi = [](int a, int lo, int hi) { return a < lo ? lo : (a > hi ? hi : a); };
  const T ts = T(kTileSize);
  TileRect r;
  r.x0 = clampi(int(k_floor((s.mean[0] - radius) / ts)), 0, v.tiles_x());
  r.x1 = clampi(int(k_floor((s.mean[0] + radius) / ts)) + 1, 0, v.tiles_x());
  r.y0 = clampi(int(k_floor((s.mean[1] - radius) / ts)), 0, v.tiles_y());
  r.y1 = clampi(int(k_floor((s.mean[1] + radius) / ts)) + 1, 0, v.tiles_y());
  return r;
}

// Forward: the splat and its screen radius (pixels, capped). False when culled: behind the near
// plane, degenerate, or touching no tile of the image (the rest of a map larger than the view),
// which is decided from the footprint before the opacity and the SH colour are evaluated.
template <class T, class S>
RRG_HD inline bool project_gaussian(const ViewT<T>& v, const GaussianInT<T, S>& g, SplatT<T>& out, T& radius) {
  {
    // A centre more than the radius cap beyond the image leaves every tile empty whatever the
    // covariance: culled before it is formed.
    const Vec3<T> p = v.R() * g.mean + v.t();
    if (!(p.z() >= v.near_plane)) return false;
    const T u = v.fx * p.x() / p.z() + v.cx, w = v.fy * p.y() / p.z() + v.cy;
    const T W = T(v.tiles_x() * kTileSize), H = T(v.tiles_y() * kTileSize);
    if (u + v.max_radius < T(0) || u - v.max_radius >= W || w + v.max_radius < T(0) || w - v.max_radius >= H) return false;
  }
  ProjectionT<T> pr;
  if (!projection_terms(v, g, pr)) return false;
  const T z = pr.p_c.z();
  out.mean[0] = v.fx * pr.p_c.x() / z + v.cx;
  out.mean[1] = v.fy * pr.p_c.y() / z + v.cy;
  const T mid = T(0.5) * (pr.A + pr.C);
  const T disc = mid * mid - pr.det;
  const T lambda_max = mid + k_sqrt(disc > T(0.1) ? disc : T(0.1));
  radius = k_ceil(T(3) * k_sqrt(lambda_max));
  if (radius > v.max_radius) radius = v.max_radius;
  if (tile_rect(v, out, radius).count() == 0) return false;
  out.conic[0] = pr.C / pr.det;
  out.conic[1] = -pr.B / pr.det;
  out.conic[2] = pr.A / pr.det;
  out.opacity = sigmoid(g.logit_opacity);
  const Vec3<T> c = sh_color<T, S>(v.sh_degree, g.sh, g.mean, v.center());
  out.color[0] = c.x();
  out.color[1] = c.y();
  out.color[2] = c.z();
  out.depth = z;
  return true;
}

// Gradients of one Gaussian's parameters from the gradient of its splat (v_sh accumulates, the rest
// is written). Recomputes the forward terms; a culled Gaussian gets zeros.
template <class T, class S>
RRG_TU_LOCAL RRG_HD inline void project_gaussian_bwd(const ViewT<T>& v, const GaussianInT<T, S>& g, const SplatT<T>& vs,
                                        Vec3<T>& v_mean, Vec3<T>& v_log_scale, Vec4<T>& v_quat,
                                        T& v_logit_opacity, Vec3<T>* v_sh) {
  v_mean.setZero();
  v_log_scale.setZero();
  v_quat.setZero();
  v_logit_opacity = T(0);
  ProjectionT<T> pr;
  if (!projection_terms(v, g, pr)) return;
  const Mat3<T> W = v.R();
  const T x = pr.p_c.x(), y = pr.p_c.y(), z = pr.p_c.z();
  // opacity: sigma = sigmoid(l)
  const T sig = sigmoid(g.logit_opacity);
  v_logit_opacity = vs.opacity * sig * (T(1) - sig);
  // colour through SH, and through the view direction into the mean
  const Vec3<T> v_color(vs.color[0], vs.color[1], vs.color[2]);
  v_mean += sh_color_bwd<T, S>(v.sh_degree, g.sh, g.mean, v.center(), v_color, v_sh);
  // p_hat and depth -> p_c
  Vec3<T> v_pc(v.fx / z * vs.mean[0], v.fy / z * vs.mean[1],
               -v.fx * x / (z * z) * vs.mean[0] - v.fy * y / (z * z) * vs.mean[1] + vs.depth);
  // conic (a, b, c) = (C, -B, A) / det -> (A, B, C)
  const T d2 = pr.det * pr.det, A = pr.A, B = pr.B, C = pr.C;
  const T va = vs.conic[0], vb = vs.conic[1], vc = vs.conic[2];
  const T vA = (-C * C * va + B * C * vb - B * B * vc) / d2;
  const T vB = (2 * B * C * va - (A * C + B * B) * vb + 2 * A * B * vc) / d2;
  const T vC = (-B * B * va + A * B * vb - A * A * vc) / d2;
  Mat2<T> G2;
  G2 << vA, vB / 2, vB / 2, vC;
  // Sigma' = J Sigma_c J^T: v_J = 2 G2 J Sigma_c, v_Sigma_c = J^T G2 J
  const Mat23<T> v_J = T(2) * G2 * pr.J * pr.Sigma_c;
  const Mat3<T> v_Sigma_c = pr.J.transpose() * G2 * pr.J;
  // J(t): d/dtx, d/dty, d/dtz
  const T tx = pr.t.x(), ty = pr.t.y();
  const T v_tx = v_J(0, 2) * (-v.fx / (z * z));
  const T v_ty = v_J(1, 2) * (-v.fy / (z * z));
  const T v_tz = v_J(0, 0) * (-v.fx / (z * z)) + v_J(0, 2) * (2 * v.fx * tx / (z * z * z)) +
                 v_J(1, 1) * (-v.fy / (z * z)) + v_J(1, 2) * (2 * v.fy * ty / (z * z * z));
  // t = p_c, or +-lim z where clamped
  if (pr.clamp_x) v_pc.z() += v_tx * tx / z;
  else v_pc.x() += v_tx;
  if (pr.clamp_y) v_pc.z() += v_ty * ty / z;
  else v_pc.y() += v_ty;
  v_pc.z() += v_tz;
  v_mean += W.transpose() * v_pc;
  // Sigma_c = W Sigma W^T, Sigma = M M^T, M = R(q) S
  const Mat3<T> v_Sigma = W.transpose() * v_Sigma_c * W;
  const Mat3<T> v_M = T(2) * v_Sigma * pr.M;
  const Mat3<T> R = quat_to_rot(pr.q);
  Mat3<T> v_R;
  for (int j = 0; j < 3; ++j) {
    v_R.col(j) = v_M.col(j) * pr.s[j];
    v_log_scale[j] = v_M.col(j).dot(R.col(j)) * pr.s[j];  // v_s * s
  }
  const Vec4<T> v_q = quat_to_rot_bwd(pr.q, v_R);
  v_quat = (v_q - pr.q * pr.q.dot(v_q)) / g.quat.norm();
}

}  // namespace rrg::kernel
