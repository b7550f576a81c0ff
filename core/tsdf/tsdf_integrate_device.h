#pragma once
// Per-voxel fusion math (paper §4.1.4 and the supplement "TSDF Color Variance Update"): the only
// copy, used by the fusion kernel on both back ends.
#include "core/common/span.h"
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

// Standard fusion with one observation of normalised distance t_obs = min(1, sdf / ε):
//   d ← (W d + t_obs) / (W + 1),  c̄_{n+1} = (n c̄_n + c_t) / (n + 1) with n = W,  W ← min(W + 1, W_max)
RRG_HD inline void fuse_sdf_color(TsdfVoxel& g, AttrVoxel& a, float t_obs, const Eigen::Vector3f& c,
                                  int max_weight) {
  const float w = float(g.weight), inv = 1.0f / (w + 1.0f);
  g.tsdf = voxel_codec::encode_tsdf((voxel_codec::decode_tsdf(g.tsdf) * w + t_obs) * inv);
  for (int k = 0; k < 3; ++k)
    a.rgb[k] = voxel_codec::encode_unit((voxel_codec::decode_unit(a.rgb[k]) * w + c[k]) * inv);
  g.weight = uint16_t(g.weight + 1 > max_weight ? max_weight : g.weight + 1);
}

// Reflection attributes, only on identification frames and only inside the band |sdf| < ε:
//   x_t = (r + g + b) / 3;  δ = x_t − μ_n;  μ_{n+1} = μ_n + δ / (n + 1);  M_{2,n+1} = M_{2,n} + δ (x_t − μ_{n+1})
//   r ← r + (m_t − r) / min(n + 1, W)   (mean of the masks so far, then an average over ~W windows)
//   π ← canonical(id) when the pixel has a plane, else unchanged
// n saturates at 65535 (the updates then continue with that count).
RRG_HD inline void fuse_reflection(AttrVoxel& v, const Eigen::Vector3f& c, float mask, int32_t plane, int window) {
  const uint32_t n1 = v.n < 65535 ? uint32_t(v.n) + 1 : 65535u;
  const float x = (c.x() + c.y() + c.z()) * (1.0f / 3.0f);
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
