#pragma once
// One Gaussian -> one splat (EWA splatting, Zwicker et al.; 3DGS): forward and backward, the only
// copy of the math. p_c = R_cw p + t_cw; Sigma = R S S^T R^T with S = diag(exp(log s)) and R from
// the normalised quaternion; Sigma' = J R_cw Sigma R_cw^T J^T + low_pass I (J the projection's
// Jacobian at p_c, its x/z and y/z clamped to 1.3 x the half field of view as in 3DGS);
// p_hat = (fx x/z + cx, fy y/z + cy); screen radius ceil(3 sqrt(lambda_max(Sigma'))) capped.
#include "core/common/fast_math.h"
#include "core/render/sh_device.h"
#include "core/render/splat.h"

#include <cmath>

namespace rrg::kernel {

// The parameters of one Gaussian, read from a GaussianSet (S is the storage's SH vector type; Sh how
// its coefficients are read, sh_coeff in sh_device.h).
template <class T, class S, class Sh = const S*>
struct GaussianInT {
  Vec3<T> mean, log_scale;
  Vec4<T> quat;  // w, x, y, z; normalised here
  T logit_opacity;
  Sh sh;  // [K, 3]
};

// e^x of the projection: exp_clamped in float (a polynomial on the host that vectorises, expf on
// CUDA), exp in double (the finite-difference references of the tests).
RRG_HD RRG_INLINE float projection_exp(float x) { return exp_clamped(x); }
RRG_HD RRG_INLINE double projection_exp(double x) { return k_exp(x); }

template <class T>
RRG_HD RRG_INLINE T sigmoid(T x) {
  return T(1) / (T(1) + projection_exp(-x));
}

// Rotation of the unit quaternion q = (w, x, y, z).
template <class T>
RRG_HD RRG_INLINE Mat3<T> quat_to_rot(const Vec4<T>& q) {
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  Mat3<T> R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

// Gradient w.r.t. the unit quaternion q of <v_R, R(q)>.
template <class T>
RRG_HD RRG_INLINE Vec4<T> quat_to_rot_bwd(const Vec4<T>& q, const Mat3<T>& g) {
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
  T qn;               // |quat| before normalising
  Mat3<T> Sigma_c;    // covariance in the camera frame
  T A, B, C;          // Sigma' entries (low-pass included)
  T det;
};

// Fills pr; false when the Gaussian is culled (behind the near plane, zero quaternion, degenerate
// Sigma'). Every term is evaluated, also for a culled Gaussian (NaN or inf there, harmless), and
// the verdict is the value returned: straight-line code that the CPU evaluates for eight Gaussians
// at once (project_cpu.cpp). The quaternion is handled component by component: Eigen's 4-float
// packet code would keep that loop scalar.
template <class T, class S, class Sh>
RRG_TU_LOCAL RRG_HD RRG_INLINE bool projection_terms(const ViewT<T>& v, const GaussianInT<T, S, Sh>& g, ProjectionT<T>& pr) {
  const Mat3<T> W = v.R();
  pr.p_c = W * g.mean + v.t();
  const T z = pr.p_c.z();
  const T lim_x = T(1.3) * T(0.5) * T(v.width) / v.fx, lim_y = T(1.3) * T(0.5) * T(v.height) / v.fy;
  const T u = pr.p_c.x() / z, w = pr.p_c.y() / z;
  pr.clamp_x = (u < -lim_x) | (u > lim_x);
  pr.clamp_y = (w < -lim_y) | (w > lim_y);
  pr.t = {(pr.clamp_x ? (u < 0 ? -lim_x : lim_x) : u) * z, (pr.clamp_y ? (w < 0 ? -lim_y : lim_y) : w) * z, z};
  pr.J << v.fx / z, T(0), -v.fx * pr.t.x() / (z * z),  //
      T(0), v.fy / z, -v.fy * pr.t.y() / (z * z);
  const T q0 = g.quat[0], q1 = g.quat[1], q2 = g.quat[2], q3 = g.quat[3];
  pr.qn = k_sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3);
  pr.q[0] = q0 / pr.qn;
  pr.q[1] = q1 / pr.qn;
  pr.q[2] = q2 / pr.qn;
  pr.q[3] = q3 / pr.qn;
  pr.s = {projection_exp(g.log_scale.x()), projection_exp(g.log_scale.y()), projection_exp(g.log_scale.z())};
  pr.M = quat_to_rot(pr.q) * pr.s.asDiagonal();
  pr.Sigma_c = W * (pr.M * pr.M.transpose()) * W.transpose();
  // Sigma' = J Sigma_c J^T, the three entries summed out (GCC keeps Eigen's 2x3 x 3x3 x 3x2 product
  // an out-of-line call inside the CPU's vector loop)
  const Mat23<T> JS = pr.J * pr.Sigma_c;
  pr.A = JS(0, 0) * pr.J(0, 0) + JS(0, 1) * pr.J(0, 1) + JS(0, 2) * pr.J(0, 2) + v.low_pass;
  pr.B = JS(0, 0) * pr.J(1, 0) + JS(0, 1) * pr.J(1, 1) + JS(0, 2) * pr.J(1, 2);
  pr.C = JS(1, 0) * pr.J(1, 0) + JS(1, 1) * pr.J(1, 1) + JS(1, 2) * pr.J(1, 2) + v.low_pass;
  pr.det = pr.A * pr.C - pr.B * pr.B;
  return (z >= v.near_plane) & (pr.qn > T(0)) & (pr.det > T(0));
}

// Whether a Gaussian centred at `mean` can touch the image: in front of the near plane, its
// projected centre within the radius cap of the image (a splat's radius never exceeds the cap).
// Cheap: drivers test it first and skip the projection of the rest of a map larger than the view.
template <class T>
RRG_HD RRG_INLINE bool centre_in_reach(const ViewT<T>& v, const Vec3<T>& mean) {
  const Vec3<T> p = v.R() * mean + v.t();
  const T u = v.fx * p.x() / p.z() + v.cx, w = v.fy * p.y() / p.z() + v.cy;
  const T W = T(v.tiles_x() * kTileSize), H = T(v.tiles_y() * kTileSize);
  const bool outside = (u + v.max_radius < T(0)) | (u - v.max_radius >= W) | (w + v.max_radius < T(0)) |
                       (w - v.max_radius >= H);
  return (p.z() >= v.near_plane) & !outside;
}

// Tiles touched by a splat of the given radius around p_hat (pixel centres at integer coordinates).
// Clamped as floats before the conversion to int, so NaN (a culled splat) gives a valid empty rect.
template <class T>
RRG_HD RRG_INLINE TileRect tile_rect(const ViewT<T>& v, const SplatT<T>& s, T radius) {
  auto clamped = [](T f, int hi) { return int(!(f > T(0)) ? T(0) : (f > T(hi) ? T(hi) : f)); };
  const T ts = T(kTileSize);
  TileRect r;
  r.x0 = clamped(k_floor((s.mean[0] - radius) / ts), v.tiles_x());
  r.x1 = clamped(k_floor((s.mean[0] + radius) / ts) + T(1), v.tiles_x());
  r.y0 = clamped(k_floor((s.mean[1] - radius) / ts), v.tiles_y());
  r.y1 = clamped(k_floor((s.mean[1] + radius) / ts) + T(1), v.tiles_y());
  return r;
}

// Forward: the splat and its screen radius (pixels, capped), with the SH evaluated to `sh_degree`.
// False when culled: behind the near plane, centre beyond the radius cap of the image, degenerate,
// or touching no tile of the image. Like projection_terms every term is evaluated and the verdict
// is the value returned (the CPU's vector loop); the drivers skip it where centre_in_reach fails.
template <class T, class S, class Sh>
RRG_HD RRG_INLINE bool project_gaussian(const ViewT<T>& v, const GaussianInT<T, S, Sh>& g, int sh_degree, SplatT<T>& out,
                                    T& radius) {
  ProjectionT<T> pr;
  bool ok = projection_terms(v, g, pr) & centre_in_reach(v, g.mean);
  const T z = pr.p_c.z();
  out.mean[0] = v.fx * pr.p_c.x() / z + v.cx;
  out.mean[1] = v.fy * pr.p_c.y() / z + v.cy;
  const T mid = T(0.5) * (pr.A + pr.C);
  const T disc = mid * mid - pr.det;
  const T lambda_max = mid + k_sqrt(disc > T(0.1) ? disc : T(0.1));
  radius = k_ceil(T(3) * k_sqrt(lambda_max));
  radius = radius > v.max_radius ? v.max_radius : radius;
  const TileRect r = tile_rect(v, out, radius);
  ok = ok & (r.x1 > r.x0) & (r.y1 > r.y0);
  out.conic[0] = pr.C / pr.det;
  out.conic[1] = -pr.B / pr.det;
  out.conic[2] = pr.A / pr.det;
  out.opacity = sigmoid(g.logit_opacity);
  const Vec3<T> c = sh_color<T>(sh_degree, g.sh, g.mean, v.center());
  out.color[0] = c.x();
  out.color[1] = c.y();
  out.color[2] = c.z();
  out.depth = z;
  return ok;
}

template <class T, class S, class Sh>
RRG_HD RRG_INLINE bool project_gaussian(const ViewT<T>& v, const GaussianInT<T, S, Sh>& g, SplatT<T>& out, T& radius) {
  return project_gaussian(v, g, v.sh_degree, out, radius);
}

// Gradients of one Gaussian's parameters from the gradient of its splat (v_sh accumulates through
// sh_grad_add, the rest is written). Recomputes the forward terms. Returns false for a Gaussian
// projection_terms culls, whose outputs are then meaningless (NaN possible): the callers write
// zeros for it. Straight-line like the forward (no early return, selects for the clamps), with
// Sigma' and the quaternion's tangent projection summed out component by component (Eigen's
// 2x2 and 4-vector packet code would keep the CPU's vector loop scalar).
template <class T, class S, class Sh, class VSh>
RRG_TU_LOCAL RRG_HD RRG_INLINE bool project_gaussian_bwd(const ViewT<T>& v, const GaussianInT<T, S, Sh>& g, int sh_degree,
                                                         const SplatT<T>& vs, Vec3<T>& v_mean, Vec3<T>& v_log_scale,
                                                         Vec4<T>& v_quat, T& v_logit_opacity, VSh v_sh) {
  ProjectionT<T> pr;
  const bool ok = projection_terms(v, g, pr);
  const Mat3<T> W = v.R();
  const T x = pr.p_c.x(), y = pr.p_c.y(), z = pr.p_c.z();
  // opacity: sigma = sigmoid(l)
  const T sig = sigmoid(g.logit_opacity);
  v_logit_opacity = vs.opacity * sig * (T(1) - sig);
  // colour through SH, and through the view direction into the mean
  const Vec3<T> v_color(vs.color[0], vs.color[1], vs.color[2]);
  v_mean = sh_color_bwd<T>(sh_degree, g.sh, g.mean, v.center(), v_color, v_sh);
  // p_hat and depth -> p_c
  Vec3<T> v_pc(v.fx / z * vs.mean[0], v.fy / z * vs.mean[1],
               -v.fx * x / (z * z) * vs.mean[0] - v.fy * y / (z * z) * vs.mean[1] + vs.depth);
  // conic (a, b, c) = (C, -B, A) / det -> (A, B, C)
  const T d2 = pr.det * pr.det, A = pr.A, B = pr.B, C = pr.C;
  const T va = vs.conic[0], vb = vs.conic[1], vc = vs.conic[2];
  const T vA = (-C * C * va + B * C * vb - B * B * vc) / d2;
  const T vB = (2 * B * C * va - (A * C + B * B) * vb + 2 * A * B * vc) / d2;
  const T vC = (-B * B * va + A * B * vb - A * A * vc) / d2;
  // Sigma' = J Sigma_c J^T with G2 = [[vA, vB/2], [vB/2, vC]] its gradient: v_J = 2 G2 J Sigma_c,
  // v_Sigma_c = J^T G2 J; GJ = G2 J row by row
  Mat23<T> GJ;
  for (int c = 0; c < 3; ++c) {
    GJ(0, c) = vA * pr.J(0, c) + (vB / 2) * pr.J(1, c);
    GJ(1, c) = (vB / 2) * pr.J(0, c) + vC * pr.J(1, c);
  }
  const Mat23<T> v_J = T(2) * (GJ * pr.Sigma_c);
  const Mat3<T> v_Sigma_c = pr.J.transpose() * GJ;
  // J(t): d/dtx, d/dty, d/dtz
  const T tx = pr.t.x(), ty = pr.t.y();
  const T v_tx = v_J(0, 2) * (-v.fx / (z * z));
  const T v_ty = v_J(1, 2) * (-v.fy / (z * z));
  const T v_tz = v_J(0, 0) * (-v.fx / (z * z)) + v_J(0, 2) * (2 * v.fx * tx / (z * z * z)) +
                 v_J(1, 1) * (-v.fy / (z * z)) + v_J(1, 2) * (2 * v.fy * ty / (z * z * z));
  // t = p_c, or +-lim z where clamped (t_x = +-lim z: its gradient goes to z as v_tx t_x / z)
  v_pc.x() += pr.clamp_x ? T(0) : v_tx;
  v_pc.y() += pr.clamp_y ? T(0) : v_ty;
  v_pc.z() += (pr.clamp_x ? v_tx * tx / z : T(0)) + (pr.clamp_y ? v_ty * ty / z : T(0)) + v_tz;
  v_mean += W.transpose() * v_pc;
  // Sigma_c = W Sigma W^T, Sigma = M M^T, M = R(q) S
  const Mat3<T> v_Sigma = W.transpose() * v_Sigma_c * W;
  const Mat3<T> v_M = T(2) * (v_Sigma * pr.M);
  const Mat3<T> R = quat_to_rot(pr.q);
  Mat3<T> v_R;
  for (int j = 0; j < 3; ++j) {
    v_R.col(j) = v_M.col(j) * pr.s[j];
    v_log_scale[j] = v_M.col(j).dot(R.col(j)) * pr.s[j];  // v_s * s
  }
  // q = quat / |quat|: v_quat = (v_q - q (q . v_q)) / |quat|
  const Vec4<T> v_q = quat_to_rot_bwd(pr.q, v_R);
  const T q_dot = pr.q[0] * v_q[0] + pr.q[1] * v_q[1] + pr.q[2] * v_q[2] + pr.q[3] * v_q[3];
  for (int k = 0; k < 4; ++k) v_quat[k] = (v_q[k] - pr.q[k] * q_dot) / pr.qn;
  return ok;
}

}  // namespace rrg::kernel
