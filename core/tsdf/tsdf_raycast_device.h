#pragma once
// Per-pixel raycasting math (pass 1 of the renderer, DESIGN.md §1): zero-crossing search along the
// ray with block-level empty-space skipping, secant refinement, and the outputs at the surface.
#include "core/common/camera.h"
#include "core/common/fast_math.h"
#include "core/tsdf/tsdf_integrate_device.h"
#include "core/tsdf/tsdf_sample_device.h"

namespace rrg::kernel {

inline constexpr int kRefineSteps = 8;     // at most, per hit
inline constexpr float kRefineTol = 1e-3f;  // stop when the bracket or |d| is smaller (voxels)

struct RayHit {
  bool hit = false;
  float z = 0.0f;              // depth along the optical axis
  Eigen::Vector3f p_w = Eigen::Vector3f::Zero();
};

// Distance (in units of the ray parameter) to leave the region [8b, 8b + 8) · s of block b that
// holds p, along dir (inv_dir = 1 / dir per axis, ±inf on an axis the ray does not move along). A
// trilinear sample at p needs its lower corner voxel floor(p / s), so no point of the region of an
// unallocated block has a valid sample.
RRG_HD inline float block_exit(const Eigen::Vector3f& p, const Eigen::Vector3f& dir, const Eigen::Vector3f& inv_dir,
                               const Eigen::Vector3i& b, float voxel_size) {
  const float block_size = voxel_size * kBlockSide;
  float t_exit = 1e30f;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0f) continue;
    const float face = float(dir[k] > 0.0f ? b[k] + 1 : b[k]) * block_size;
    t_exit = min_f(t_exit, (face - p[k]) * inv_dir[k]);
  }
  return max_f(t_exit, 0.0f);
}

// March from depth z_start to z_end along o + z · d (d has unit z in the camera frame) and return
// the first +/− zero crossing of the trilinear TSDF, refined by regula falsi until the bracket or
// the sample's own distance |d| is below kRefineTol voxels. `cache` holds the blocks looked up
// (shade() of the hit reuses them). Steps:
//   block of floor(p / s) not allocated       → to the ray's exit from that block (DDA over blocks);
//   sample invalid (a corner unobserved)      → one voxel; when no corner is observed, to the exit of
//                                                the box of cells sharing a corner with this one;
//   f = d/ε > 0                               → max(s, f · ε): the TSDF is the distance to the surface
//                                                along the fusing rays, so a step may overshoot it only
//                                                into the band behind it (f ≥ −1), where the crossing
//                                                is still bracketed (as Open3D's march steps);
//                                                where fusion's band ε(d) was wider than ε
//                                                (truncation_band.h) f · ε is less than that
//                                                distance: a shorter step, never a longer one;
//   f ≤ 0 without a positive sample before    → one voxel (entering from behind a surface).
// One ray's march as a state machine: march_begin() sets it up, each march_step() takes one
// sample (a crossing's refinement included) and returns true when the ray is done (s.hit says how).
// march() runs one ray to the end; the CPU raycast interleaves the steps of a few rays instead, so
// that the core overlaps their dependent chains of loads (tsdf_raycast_impl.h). Either way each ray
// takes the same samples and gives the same hit.
struct MarchState {
  Eigen::Vector3f o, d, inv_d;
  float len, voxel_z, nudge_z, truncation, z_end;
  float z, z_prev = 0.0f, f_prev = 0.0f;
  bool have_prev = false;
  RayHit hit;
};

RRG_HD RRG_INLINE void march_begin(MarchState& m, const VolumeView& vol, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                   float truncation, float z_start, float z_end) {
  m.o = o;
  m.d = d;
  m.len = d.norm();  // metres per unit of z
  m.inv_d = Eigen::Vector3f(1.0f / d.x(), 1.0f / d.y(), 1.0f / d.z());
  m.voxel_z = vol.voxel_size / m.len;          // one voxel along the ray
  m.nudge_z = 1e-3f * vol.voxel_size / m.len;  // 1/1000 voxel along the ray
  m.truncation = truncation;
  m.z_end = z_end;
  m.z = z_start;
  m.z_prev = 0.0f;
  m.f_prev = 0.0f;
  m.have_prev = false;
  m.hit = RayHit{};
}

RRG_TU_LOCAL RRG_HD inline bool march_step(const VolumeView& vol, MarchState& m, BlockCache& cache) {
  if (!(m.z < m.z_end)) return true;
  const float s = vol.voxel_size;
  const Eigen::Vector3f& d = m.d;
  const Eigen::Vector3f p = m.o + m.z * d;
  Corners corners;
  const Sample sample = trilinear_corners(vol, p, cache, corners);
  if (sample == Sample::NoBlock) {  // empty space: skip the whole block
    m.z += block_exit(p, d, m.inv_d, corners.block, s) + m.nudge_z;
    m.have_prev = false;
    return false;
  }
  if (sample == Sample::Unobserved) {
    // No corner of the cell observed: every cell sharing one of its corners is invalid too, so
    // no valid sample lies in the box g − 1 .. g + 2 (voxel units) around it; skip to its exit,
    // which is at least one voxel away. Otherwise one voxel.
    float step = m.voxel_z;
    if (corners.missing == 8) {
      step = 1e30f;
      for (int k = 0; k < 3; ++k)
        if (d[k] != 0.0f) step = min_f(step, (d[k] > 0.0f ? 2.0f - corners.f[k] : 1.0f + corners.f[k]) * s * fabsf(m.inv_d[k]));
    }
    m.z += step;
    m.have_prev = false;
    return false;
  }
  const float f = trilinear(corners.t, corners.f) * voxel_codec::kInvTsdfScale;
  if (m.have_prev && m.f_prev > 0.0f && f <= 0.0f) {
    // Regula falsi with the Illinois modification on the bracket [z_prev, z]: the trilinear TSDF
    // is cubic along the ray, so plain secant steps can stall on one side of a large bracket.
    float za = m.z_prev, fa = m.f_prev, zb = m.z, fb = f;
    float zc = za + (zb - za) * fa / (fa - fb);
    int side = 0;
    for (int it = 0; it < kRefineSteps && (zb - za) * m.len > kRefineTol * s; ++it) {
      float fc;
      if (!sample_tsdf(vol, m.o + zc * d, cache, fc)) break;
      // |d| = |f| ε(d) is the distance to the surface; |f| ε may be less by ε(d) / ε (about 4 at
      // 4 m), which at 10⁻³ voxel is still far below the depth noise.
      if (fabsf(fc) * m.truncation <= kRefineTol * s) break;
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
    m.hit.hit = true;
    m.hit.z = zc;
    m.hit.p_w = m.o + zc * d;
    return true;
  }
  m.have_prev = true;
  m.z_prev = m.z;
  m.f_prev = f;
  m.z += f > 0.0f ? max_f(m.voxel_z, f * m.truncation / m.len) : m.voxel_z;
  return false;
}

// A begun march run to its end: its hit.
RRG_TU_LOCAL RRG_HD inline RayHit march_run(const VolumeView& vol, MarchState& m, BlockCache& cache) {
  while (!march_step(vol, m, cache)) {
  }
  return m.hit;
}

RRG_TU_LOCAL RRG_HD inline RayHit march(const VolumeView& vol, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                           float truncation, float z_start, float z_end, BlockCache& cache) {
  MarchState m;
  march_begin(m, vol, o, d, truncation, z_start, z_end);
  return march_run(vol, m, cache);
}

struct SurfaceSample {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();
  float variance = 0.0f;     // C_var = Σ w_i σ_i² / (Σ w_i + eps) over voxels with n_i > 0
  float reflection = 0.0f;   // R_raw, same weighting of r_i
  int32_t plane = 0;         // π of the nearest voxel, canonical through the remap table
};

// The voxels g + (−1..2)³ around the cell g .. g + 1 of a surface point: the 8 corners of the cell
// and the 24 further voxels the central differences of the trilinear TSDF one voxel apart need.
// Their blocks (at most two per axis) are resolved once, and per axis the block (0 or 1) and the
// in-block offset of each of the four coordinates are tabulated, so a read costs a few adds.
struct Neighbourhood {
  const VolumeView& vol;
  int64_t first[8];   // voxel 0 of block (block of g − 1) + (bit 0: +x, 1: +y, 2: +z); −1 when not resident
  int block[3][4];    // per axis k, coordinate g − 1 + i: 0 in the first block, 2^k in the next
  int offset[3][4];   // per axis: local coordinate × stride (1, 8, 64)
  // Pool index of voxel g − 1 + (x, y, z), x, y, z in 0..3; −1 when missing or unobserved.
  RRG_HD RRG_INLINE int64_t at(int x, int y, int z) const {
    const int64_t b = first[block[0][x] | block[1][y] | block[2][z]];
    if (b < 0) return -1;
    const int64_t v = b + offset[0][x] + offset[1][y] + offset[2][z];
    return vol.geometry[v].weight > 0 ? v : -1;
  }
};

// Normal and attributes at a surface point p (trilinear, as the supplement's C_var); the normal,
// the colour and the reflection attributes (π, R_raw, C_var) only when asked for (left 0
// otherwise; without the normal the 24 voxels beyond the cell are not read). `cache` may hold
// blocks from the march.
RRG_TU_LOCAL RRG_HD inline SurfaceSample shade(const VolumeView& vol, const Eigen::Vector3f& p, Span<const int32_t> remap,
                                  BlockCache& cache, bool want_color, bool want_reflection, bool want_normal) {
  constexpr float kEps = 1e-6f;
  SurfaceSample out;
  const Eigen::Vector3f q = p * (1.0f / vol.voxel_size);
  const Eigen::Vector3i g(floor_to_int(q.x()), floor_to_int(q.y()), floor_to_int(q.z()));
  const Eigen::Vector3f f = q - g.cast<float>();
  Neighbourhood nb{vol, {}, {}, {}};
  int b_lo[3], span[3];  // block of g − 1 per axis; whether g + 2 is in the next block
  RRG_UNROLL
  for (int k = 0; k < 3; ++k) {
    const int lo = g[k] - 1, stride = k == 0 ? 1 : (k == 1 ? kBlockSide : kBlockSide * kBlockSide);
    b_lo[k] = block_of(lo);
    RRG_UNROLL
    for (int i = 0; i < 4; ++i) {
      nb.block[k][i] = (block_of(lo + i) - b_lo[k]) << k;
      nb.offset[k][i] = local_of(lo + i) * stride;
    }
    span[k] = nb.block[k][3] >> k;
  }
  RRG_UNROLL
  for (int o = 0; o < 8; ++o) {
    const int dx = o & 1, dy = (o >> 1) & 1, dz = o >> 2;
    nb.first[o] = -1;
    if (dx > span[0] || dy > span[1] || dz > span[2]) continue;
    const int32_t blk = cached_block(vol, b_lo[0] + dx, b_lo[1] + dy, b_lo[2] + dz, cache);
    if (blk >= 0) nb.first[o] = int64_t(blk) * kBlockVoxels;
  }
  // d/ε of the cell's corners (neighbourhood coordinates 1..2) and of each corner's outward face
  // neighbour along each axis (that coordinate 0 or 3): the 32 voxels the normal needs, read once.
  float tc[8], tn[3][8];
  int64_t corner[8];
  RRG_UNROLL
  for (int c = 0; c < 8; ++c) {
    corner[c] = nb.at(1 + (c & 1), 1 + ((c >> 1) & 1), 1 + (c >> 2));
    if (corner[c] < 0) return out;  // a corner of the cell unobserved: no trilinear value here
    tc[c] = voxel_codec::decode_tsdf(vol.geometry[corner[c]].tsdf);
  }
  // The corners' attributes (another array than the TSDF the march has been reading, so not in
  // the caches yet): requested now, read after the 24 neighbours below (when the normal is asked for).
  if (want_color || want_reflection)
    for (int c = 0; c < 8; ++c) RRG_PREFETCH(&vol.attributes[corner[c]]);
  bool neighbours = true;  // all 24 outward neighbours observed
  if (want_normal) {
    RRG_UNROLL
    for (int c = 0; c < 8; ++c) {
      const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
      const int64_t v[3] = {nb.at(3 * dx, 1 + dy, 1 + dz), nb.at(1 + dx, 3 * dy, 1 + dz), nb.at(1 + dx, 1 + dy, 3 * dz)};
      for (int k = 0; k < 3; ++k) {
        neighbours = neighbours && v[k] >= 0;
        tn[k][c] = v[k] >= 0 ? voxel_codec::decode_tsdf(vol.geometry[v[k]].tsdf) : 0.0f;
      }
    }
  }
  float w[8];
  for (int c = 0; c < 8; ++c) w[c] = corner_weight(f, c);
  if (want_color)
    for (int i = 0; i < 8; ++i) out.color += w[i] * voxel_color(vol.attributes[corner[i]]);
  if (want_reflection) {
    float w_refl = 0.0f;
    for (int i = 0; i < 8; ++i) {
      const AttrVoxel& a = vol.attributes[corner[i]];
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
  }
  if (!want_normal) return out;
  // Normal: central differences of the trilinear TSDF one voxel apart,
  //   f(p + s e_k) − f(p − s e_k) = Σ_c w_c (d(c + e_k) − d(c − e_k)),
  // when all 24 voxels beyond the cell are observed; within the cell otherwise.
  Eigen::Vector3f grad = Eigen::Vector3f::Zero();
  if (neighbours) {  // along axis k, corner c's other neighbour is the corner c ^ 2^k
    RRG_UNROLL
    for (int c = 0; c < 8; ++c)
      RRG_UNROLL
      for (int k = 0; k < 3; ++k) {
        const int bit = 1 << k;
        grad[k] += w[c] * ((c & bit) ? tn[k][c] - tc[c ^ bit] : tc[c ^ bit] - tn[k][c]);
      }
  } else {  // gradient of the trilinear interpolant inside the cell
    const auto lerp = [](float a, float b, float u) { return a + (b - a) * u; };
    grad.x() = lerp(lerp(tc[1] - tc[0], tc[3] - tc[2], f.y()), lerp(tc[5] - tc[4], tc[7] - tc[6], f.y()), f.z());
    grad.y() = lerp(lerp(tc[2] - tc[0], tc[3] - tc[1], f.x()), lerp(tc[6] - tc[4], tc[7] - tc[5], f.x()), f.z());
    grad.z() = lerp(lerp(tc[4] - tc[0], tc[5] - tc[1], f.x()), lerp(tc[6] - tc[2], tc[7] - tc[3], f.x()), f.y());
  }
  const float n = grad.norm();
  if (n > 0.0f) out.normal = grad / n;
  return out;
}

}  // namespace rrg::kernel
