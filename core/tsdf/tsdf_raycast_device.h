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

// The voxels base + (−1..2)³ around the cell of a surface point: the 8 corners of the cell and the
// 24 further voxels the central differences of the trilinear TSDF one voxel apart need. Their
// blocks (at most two per axis) are resolved once, so the normal costs 32 voxel reads instead of
// six full trilinear samples.
struct Neighbourhood {
  const VolumeView& vol;
  Eigen::Vector3i lo;  // voxel base − 1
  int64_t first[8];    // voxel 0 of block (lo block + bit offsets), −1 when not resident
  // Pool index of voxel lo + (x, y, z), x, y, z in 0..3; −1 when missing or unobserved.
  RRG_HD int64_t at(int x, int y, int z) const {
    const int gx = lo.x() + x, gy = lo.y() + y, gz = lo.z() + z;
    const int o = (block_of(gx) - block_of(lo.x())) | ((block_of(gy) - block_of(lo.y())) << 1) |
                  ((block_of(gz) - block_of(lo.z())) << 2);
    if (first[o] < 0) return -1;
    const int64_t v = first[o] + local_index(local_of(gx), local_of(gy), local_of(gz));
    return vol.geometry[v].weight > 0 ? v : -1;
  }
};

// Attributes at a surface point p (trilinear, as the supplement's C_var).
RRG_HD inline SurfaceSample shade(const VolumeView& vol, const Eigen::Vector3f& p, Span<const int32_t> remap) {
  constexpr float kEps = 1e-6f;
  SurfaceSample out;
  BlockCache cache;
  const float s = vol.voxel_size;
  const Eigen::Vector3f q = p / s;
  const Eigen::Vector3f b(floorf(q.x()), floorf(q.y()), floorf(q.z()));
  const Eigen::Vector3f f = q - b;
  Neighbourhood nb{vol, Eigen::Vector3i(int(b.x()) - 1, int(b.y()) - 1, int(b.z()) - 1), {}};
  const int bx = block_of(nb.lo.x()), by = block_of(nb.lo.y()), bz = block_of(nb.lo.z());
  const int ex = block_of(nb.lo.x() + 3) - bx, ey = block_of(nb.lo.y() + 3) - by, ez = block_of(nb.lo.z() + 3) - bz;
  for (int o = 0; o < 8; ++o) {
    const int dx = o & 1, dy = (o >> 1) & 1, dz = o >> 2;
    nb.first[o] = -1;
    if (dx > ex || dy > ey || dz > ez) continue;
    const int32_t blk = cached_block(vol, bx + dx, by + dy, bz + dz, cache);
    if (blk >= 0) nb.first[o] = int64_t(blk) * kBlockVoxels;
  }
  // The cell's corners (offset 1 in the neighbourhood) and their trilinear weights.
  int64_t corner[8];
  float w[8];
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
    corner[c] = nb.at(1 + dx, 1 + dy, 1 + dz);
    if (corner[c] < 0) return out;
    w[c] = (dx ? f.x() : 1.0f - f.x()) * (dy ? f.y() : 1.0f - f.y()) * (dz ? f.z() : 1.0f - f.z());
  }
  float w_refl = 0.0f;
  for (int i = 0; i < 8; ++i) {
    const AttrVoxel& a = vol.attributes[corner[i]];
    out.color += w[i] * voxel_color(a);
    if (a.n > 0) {
      out.variance += w[i] * voxel_variance(a);
      out.reflection += w[i] * voxel_codec::decode_unit(a.r);
      w_refl += w[i];
    }
  }
  out.variance /= (w_refl + kEps);
  out.reflection /= (w_refl + kEps);
  // π of the nearest voxel (a corner of the cell), canonical through the remap table.
  const int nearest = (f.x() >= 0.5f ? 1 : 0) | (f.y() >= 0.5f ? 2 : 0) | (f.z() >= 0.5f ? 4 : 0);
  out.plane = canonical_plane(remap, int32_t(vol.attributes[corner[nearest]].plane));
  // Normal: central differences of the trilinear TSDF one voxel apart,
  //   f(p + s e_k) − f(p − s e_k) = Σ_c w_c (d(c + e_k) − d(c − e_k)),
  // when all 24 voxels beyond the cell are observed; within the cell otherwise.
  Eigen::Vector3f grad = Eigen::Vector3f::Zero();
  bool ok = true;
  for (int k = 0; k < 3 && ok; ++k)
    for (int c = 0; c < 8 && ok; ++c) {
      int x = 1 + (c & 1), y = 1 + ((c >> 1) & 1), z = 1 + (c >> 2);
      int xp = x, yp = y, zp = z, xm = x, ym = y, zm = z;
      if (k == 0) ++xp, --xm;
      if (k == 1) ++yp, --ym;
      if (k == 2) ++zp, --zm;
      const int64_t vp = nb.at(xp, yp, zp), vm = nb.at(xm, ym, zm);
      if (vp < 0 || vm < 0) {
        ok = false;
        break;
      }
      grad[k] += w[c] * (voxel_codec::decode_tsdf(vol.geometry[vp].tsdf) - voxel_codec::decode_tsdf(vol.geometry[vm].tsdf));
    }
  if (!ok) {  // gradient of the trilinear interpolant inside the cell
    float t[8];
    for (int i = 0; i < 8; ++i) t[i] = voxel_codec::decode_tsdf(vol.geometry[corner[i]].tsdf);
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
