#pragma once
// Per-voxel fusion math (paper §4.1.4 and the supplement "TSDF Color Variance Update"): the only
// copy, used by the fusion kernel on both back ends.
#include "core/common/camera.h"
#include "core/common/hd.h"
#include "core/common/span.h"
#include "core/tsdf/fusion_pixel.h"
#include "core/tsdf/truncation_band.h"
#include "core/tsdf/voxel.h"

#include <Eigen/Core>

namespace rrg::kernel {

RRG_HD inline Eigen::Vector3f to_color(const Eigen::Vector3f& c) { return c; }
RRG_HD inline Eigen::Vector3f to_color(const Rgb8& c) {
  return Eigen::Vector3f(float(c.r), float(c.g), float(c.b)) * (1.0f / 255.0f);
}

// Canonical plane id through the remap table of global plane maintenance (supplement): ids inside
// the table map to table[id] (when >= 0), others to themselves; negative ids mean none (0).
RRG_HD inline int32_t canonical_plane(Span<const int32_t> remap, int32_t id) {
  if (id <= 0) return 0;
  if (id < remap.size && remap[id] >= 0) return remap[id];
  return id;
}

// What the per-voxel tests need of the frame's camera, computed once per frame.
struct VoxelProjection {
  float fx, fy, cx, cy;
  float inv_fx, inv_fy;
  float width, height;  // of the fusion-pixel image
  TruncationBand band;  // ε(d)
};

inline VoxelProjection voxel_projection(const Intrinsics& K, int width, int height, const TruncationBand& band) {
  return {K.fx, K.fy, K.cx, K.cy, 1.0f / K.fx, 1.0f / K.fy, float(width), float(height), band};
}

// The nearest pixel (u, v) of a voxel at camera-frame position p_c; false when it is behind the
// camera or outside the image. Nearest pixel: floor(x + 0.5). The range test runs on the floats (it
// also rejects NaN and coordinates too large for an int); on [0, size) the truncating conversion is
// the floor. Straight-line (u, v are set either way) so that the CPU evaluates a row of voxels at
// once (tsdf_integrate_cpu.cpp).
RRG_HD RRG_INLINE bool voxel_pixel(const VoxelProjection& vp, const Eigen::Vector3f& p_c, int& u, int& v) {
  const float inv_z = 1.0f / p_c.z();  // K.project with one division
  const float uf = vp.fx * p_c.x() * inv_z + vp.cx + 0.5f;
  const float vf = vp.fy * p_c.y() * inv_z + vp.cy + 0.5f;
  const bool ok = (p_c.z() > 0.0f) & (uf >= 0.0f) & (vf >= 0.0f) & (uf < vp.width) & (vf < vp.height);
  u = ok ? int(uf) : 0;
  v = ok ? int(vf) : 0;
  return ok;
}

// How a voxel at p_c is fused from its pixel (u, v) with fusion data px (tsdf_integrate_impl.h's
// integrate() explains the tests): not at all, as free space beyond the band (t = 1), or inside
// the band, where identification frames also update the reflection attributes. Straight-line.
struct VoxelFusion {
  enum Kind : int32_t { kNone = 0, kFreeSpace = 1, kBand = 2 };
  float t;      // min(1, sdf / ε(d)), the observation fused
  int32_t kind;
};

RRG_HD RRG_INLINE VoxelFusion voxel_fusion(const VoxelProjection& vp, const FusionPixel& px, int u, int v,
                                           const Eigen::Vector3f& p_c) {
  const Eigen::Vector3f P((float(u) - vp.cx) * vp.inv_fx * px.d, (float(v) - vp.cy) * vp.inv_fy * px.d, px.d);
  const Eigen::Vector3f dp = p_c - P;
  const float sdf = px.nx * dp.x() + px.ny * dp.y() + px.nz * dp.z();
  const float eps = vp.band.at(px.d);  // ε(d) of this pixel's observation
  const bool skipped = !(px.d > 0.0f) | (sdf < -eps);  // no pixel data; behind the band
  const bool in_band = sdf < eps;
  const bool near_point = !(dp.squaredNorm() > eps * eps);
  const float ratio = sdf / eps;  // (computed unconditionally: a division under the select keeps the loop scalar)
  VoxelFusion f;
  f.t = sdf >= eps ? 1.0f : ratio;
  f.kind = skipped ? VoxelFusion::kNone
                   : (!in_band ? VoxelFusion::kFreeSpace : (near_point ? VoxelFusion::kBand : VoxelFusion::kNone));
  return f;
}

// Standard fusion with one observation of normalised distance t_obs = min(1, sdf / ε(d)):
//   d ← (W d + t_obs) / (W + 1),  c̄_{n+1} = (n c̄_n + c_t) / (n + 1) with n = W,  W ← min(W + 1, W_max)
RRG_HD inline void fuse_sdf_color(TsdfVoxel& g, AttrVoxel& a, float t_obs, const Eigen::Vector3f& c,
                                  int max_weight) {
  const float w = float(g.weight), inv = 1.0f / (w + 1.0f);
  g.tsdf = voxel_codec::encode_tsdf((voxel_codec::decode_tsdf(g.tsdf) * w + t_obs) * inv);
  for (int k = 0; k < 3; ++k)
    a.rgb[k] = voxel_codec::encode_unit((voxel_codec::decode_unit(a.rgb[k]) * w + c[k]) * inv);
  g.weight = uint16_t(g.weight + 1 > max_weight ? max_weight : g.weight + 1);
}

// Reflection attributes, only on identification frames and only inside the band |sdf| < ε(d):
//   x_t = (r + g + b) / 3;  δ = x_t − μ_n;  μ_{n+1} = μ_n + δ / (n + 1);  M_{2,n+1} = M_{2,n} + δ (x_t − μ_{n+1})
//   r ← r + (m_t − r) / min(n + 1, W)   (mean of the masks so far, then an average over ~W windows)
//   π ← canonical(id) when the pixel has a plane, else unchanged
// n saturates at 65535 (the updates then continue with that count).
RRG_HD inline void fuse_reflection(AttrVoxel& v, const Eigen::Vector3f& c, float mask, int32_t plane, int window) {
  const uint32_t n1 = v.n < 65535 ? uint32_t(v.n) + 1 : 65535u;
  const float x = welford_intensity(c);
  const float delta = x - v.mu;
  v.mu += delta / float(n1);
  v.m2 += delta * (x - v.mu);
  const float r = voxel_codec::decode_unit(v.r);
  const float count = float(n1 < uint32_t(window) ? n1 : uint32_t(window));
  v.r = voxel_codec::encode_unit(r + (mask - r) / count);
  v.n = uint16_t(n1);
  if (plane > 0) v.plane = uint16_t(plane > 65535 ? 65535 : plane);
}

}  // namespace rrg::kernel
