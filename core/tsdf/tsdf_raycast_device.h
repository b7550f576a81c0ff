#pragma once
// Per-pixel raycasting math (pass 1 of the renderer, DESIGN.md §1): zero-crossing search along the
// ray with block-level empty-space skipping, secant refinement, and the outputs at the surface.
#include "core/common/camera.h"
#include "core/tsdf/tsdf_integrate_device.h"
#include "core/tsdf/tsdf_sample_device.h"

namespace rrg::kernel {

inline constexpr int kRefineSteps = 8;     // at most, per hit
inline constexpr float kRefineTol = 1e-3f;  // stop when the bracket is shorter (voxels)

struct RayHit {
  bool hit = false;
  float z = 0.0f;              // depth along the optical axis
  Eigen::Vector3f p_w = Eigen::Vector3f::Zero();
};

// Distance (in units of the ray parameter) to leave the block region [8b, 8b + 8) · s that holds
// p along dir. A trilinear sample at p needs its lower corner voxel floor(p / s), so no point of the
// region of an unallocated block has a valid sample.
RRG_HD inline float block_exit(const Eigen::Vector3f& p, const Eigen::Vector3f& dir, float voxel_size) {
  const float block_size = voxel_size * kBlockSide;
  float t_exit = 1e30f;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0f) continue;
    const float lo = floorf(p[k] / block_size) * block_size, hi = lo + block_size;
    const float t = ((dir[k] > 0.0f ? hi : lo) - p[k]) / dir[k];
    t_exit = fminf(t_exit, t);
  }
  return fmaxf(t_exit, 0.0f);
}

// March from depth z_start to z_end along o + z · d (d has unit z in the camera frame) and return
// the first +/− zero crossing of the trilinear TSDF, refined by regula falsi. Steps:
//   block of floor(p / s) not allocated       → to the ray's exit from that block (DDA over blocks);
//   sample invalid (a corner unobserved)      → one voxel;
//   f = d/ε > 0                               → max(s, 0.8 · f · ε) (the TSDF is a distance bound);
//   f ≤ 0 without a positive sample before    → one voxel (entering from behind a surface).
RRG_HD inline RayHit march(const VolumeView& vol, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                           float truncation, float z_start, float z_end) {
  RayHit hit;
  BlockCache cache;
  const float len = d.norm();           // metres per unit of z
  const float s = vol.voxel_size;
  float z = z_start, z_prev = 0.0f, f_prev = 0.0f;
  bool have_prev = false;
  while (z < z_end) {
    const Eigen::Vector3f p = o + z * d;
    const Eigen::Vector3i g(int(floorf(p.x() / s)), int(floorf(p.y() / s)), int(floorf(p.z() / s)));
    if (voxel_at(vol, g, cache) < 0) {  // empty space: skip the whole block
      z += block_exit(p, d, s) + 1e-3f * s / len;
      have_prev = false;
      continue;
    }
    float f;
    if (!sample_tsdf(vol, p, cache, f)) {
      z += s / len;
      have_prev = false;
      continue;
    }
    if (have_prev && f_prev > 0.0f && f <= 0.0f) {
      // Regula falsi with the Illinois modification on the bracket [z_prev, z]: the trilinear TSDF
      // is cubic along the ray, so plain secant steps can stall on one side of a large bracket.
      float za = z_prev, fa = f_prev, zb = z, fb = f;
      float zc = za + (zb - za) * fa / (fa - fb);
      int side = 0;
      for (int it = 0; it < kRefineSteps && (zb - za) * len > kRefineTol * s; ++it) {
        float fc;
        if (!sample_tsdf(vol, o + zc * d, cache, fc)) break;
        if (fc > 0.0f) {
          za = zc;
          fa = fc;
          if (side == 1) fb *= 0.5f;
          side = 1;
        } else {
          zb = zc;
          fb = fc;
          if (side == -1) fa *= 0.5f;
          side = -1;
        }
        if (fa - fb <= 0.0f) break;
        zc = za + (zb - za) * fa / (fa - fb);
      }
      hit.hit = true;
      hit.z = zc;
      hit.p_w = o + zc * d;
      return hit;
    }
    have_prev = true;
    z_prev = z;
    f_prev = f;
    const float step = f > 0.0f ? fmaxf(s, 0.8f * f * truncation) : s;  // metres
    z += step / len;
  }
  return hit;
}

struct SurfaceSample {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();
  float variance = 0.0f;     // C_var = Σ w_i σ_i² / (Σ w_i + eps) over voxels with n_i > 0
  float reflection = 0.0f;   // R_raw, same weighting of r_i
  int32_t plane = 0;         // π of the nearest voxel, canonical through the remap table
};

// Attributes at a surface point p (trilinear, as the supplement's C_var).
RRG_HD inline SurfaceSample shade(const VolumeView& vol, const Eigen::Vector3f& p, Span<const int32_t> remap) {
  constexpr float kEps = 1e-6f;
  SurfaceSample out;
  BlockCache cache;
  Corners c;
  if (!trilinear_corners(vol, p, cache, c)) return out;
  float w_refl = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const AttrVoxel& a = vol.attributes[c.v[i]];
    out.color += c.w[i] * voxel_color(a);
    if (a.n > 0) {
      out.variance += c.w[i] * voxel_variance(a);
      out.reflection += c.w[i] * voxel_codec::decode_unit(a.r);
      w_refl += c.w[i];
    }
  }
  out.variance /= (w_refl + kEps);
  out.reflection /= (w_refl + kEps);
  const float s = vol.voxel_size;
  const Eigen::Vector3i g(int(floorf(p.x() / s + 0.5f)), int(floorf(p.y() / s + 0.5f)), int(floorf(p.z() / s + 0.5f)));
  if (const int64_t v = voxel_at(vol, g, cache); v >= 0)
    out.plane = canonical_plane(remap, int32_t(vol.attributes[v].plane));
  // Normal: central differences of the trilinear TSDF one voxel apart; within the cell otherwise.
  Eigen::Vector3f grad;
  bool ok = true;
  for (int k = 0; k < 3 && ok; ++k) {
    Eigen::Vector3f e = Eigen::Vector3f::Zero();
    e[k] = s;
    float fp = 0.0f, fm = 0.0f;
    ok = sample_tsdf(vol, p + e, cache, fp) && sample_tsdf(vol, p - e, cache, fm);
    grad[k] = fp - fm;
  }
  if (!ok) {  // gradient of the trilinear interpolant inside the cell
    const Eigen::Vector3f q = p / s;
    const Eigen::Vector3f f(q.x() - floorf(q.x()), q.y() - floorf(q.y()), q.z() - floorf(q.z()));
    float t[8];
    for (int i = 0; i < 8; ++i) t[i] = voxel_codec::decode_tsdf(vol.geometry[c.v[i]].tsdf);
    const auto lerp = [](float a, float b, float u) { return a + (b - a) * u; };
    grad.x() = lerp(lerp(t[1] - t[0], t[3] - t[2], f.y()), lerp(t[5] - t[4], t[7] - t[6], f.y()), f.z());
    grad.y() = lerp(lerp(t[2] - t[0], t[3] - t[1], f.x()), lerp(t[6] - t[4], t[7] - t[5], f.x()), f.z());
    grad.z() = lerp(lerp(t[4] - t[0], t[5] - t[1], f.x()), lerp(t[6] - t[2], t[7] - t[3], f.x()), f.y());
  }
  const float n = grad.norm();
  if (n > 0.0f) out.normal = grad / n;
  return out;
}

}  // namespace rrg::kernel
