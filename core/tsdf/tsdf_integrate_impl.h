#pragma once
// The body of integrate() (tsdf_integrate.h), templated on the back-end tag and the colour type;
// instantiated by tsdf_integrate_cpu.cpp and tsdf_integrate_cuda.cu.
#include "core/common/camera.h"
#include "core/tsdf/fusion_pixel.h"
#include "core/tsdf/tsdf_integrate_device.h"

namespace rrg::kernel {

inline constexpr float kMinCos = 0.2f;

struct FusionPixelArgs {
  ImageView<const float> depth;              // D_k, metres
  ImageView<const Eigen::Vector3f> normals;  // N_k^l, 0 = none
  Intrinsics K;
  float min_depth, max_depth;
  ImageView<FusionPixel> out;
};

template <class Backend>
void fusion_pixels(Backend backend, const FusionPixelArgs& a) {
  const FusionPixelArgs args = a;
  const int w = a.depth.width;
  parallel_for(backend, a.depth.size(), [=] RRG_HD(int64_t i) {
    const int u = int(i % w), v = int(i / w);
    const float d = args.depth[i];
    FusionPixel px;
    if (d >= args.min_depth && d <= args.max_depth) {
      const Eigen::Vector3f n = args.normals[i];
      const Eigen::Vector3f P = args.K.unproject(float(u), float(v), d);
      if (-n.dot(P) >= kMinCos * P.norm()) {  // fails for n = 0 too
        px = {n.x(), n.y(), n.z(), d};
      }
    }
    args.out[i] = px;
  });
}

template <class ColorT>
struct IntegrateArgs {
  ImageView<const FusionPixel> pixels;     // from D_k and N_k^l (fusion_pixels)
  ImageView<const ColorT> color;           // C_k, registered to the depth
  Intrinsics K;
  Eigen::Matrix3f R_cw;                    // world -> camera
  Eigen::Vector3f t_cw;
  float voxel_size, truncation;
  int max_weight, window;
  Span<const int32_t> active;              // blocks touched by this frame
  Span<const uint64_t> block_keys;
  Span<TsdfVoxel> geometry;
  Span<AttrVoxel> attributes;
  Span<uint64_t> versions;
  uint64_t version;
  bool reflection;                         // identification frame: update μ, M_2, n, r, π
  ImageView<const int32_t> plane_ids;      // I_k^g
  ImageView<const uint8_t> mask;           // predicted reflection mask
  Span<const int32_t> remap;               // plane id -> canonical id
};

// Every voxel of every active block. The voxel p projects to pixel u with depth D(u),
// surface point P = D(u) K^-1 [u, 1] and normal n (N_k^l); its signed distance is the
// point-to-plane sdf = n · (p − P), which stays a metric distance on oblique surfaces where the
// projective D(u) − z overestimates it by 1 / cos θ. Pixels without a normal (image border, next to
// a hole) or seen at grazing angles (cos θ < kMinCos) are not fused (FusionPixel). Inside the band
// the plane is trusted only within ε of P (|p − P| <= ε: its error is then at most ε² / 2ρ for a
// surface of curvature radius ρ); farther voxels that are not free space (sdf < ε) are left alone.
// Voxels with sdf < −ε are skipped; the others fuse min(1, sdf / ε).
template <class Backend, class ColorT>
void integrate(Backend backend, const IntegrateArgs<ColorT>& a) {
  const IntegrateArgs<ColorT> args = a;
  const float inv_fx = 1.0f / a.K.fx, inv_fy = 1.0f / a.K.fy, inv_trunc = 1.0f / a.truncation;
  const Eigen::Vector3f step_x = a.R_cw.col(0) * a.voxel_size;  // camera-frame step of one voxel in x
  const float width = float(a.pixels.width), height = float(a.pixels.height);
  // One work item per row of 8 voxels along x (a block has 64): the block's data is decoded once
  // and the camera-frame position advances by one vector add per voxel.
  parallel_for(backend, a.active.size * (kBlockVoxels / kBlockSide), [=] RRG_HD(int64_t item) {
    const int32_t block = args.active[item / (kBlockVoxels / kBlockSide)];
    const int row = int(item % (kBlockVoxels / kBlockSide));  // y + 8 z
    if (row == 0) args.versions[block] = args.version;
    const Eigen::Vector3i g0 = block_coord(args.block_keys[block]) * int(kBlockSide) + Eigen::Vector3i(0, row & 7, row >> 3);
    Eigen::Vector3f p_c = args.R_cw * (g0.cast<float>() * args.voxel_size) + args.t_cw;
    const int64_t k0 = int64_t(block) * kBlockVoxels + int64_t(row) * kBlockSide;
    for (int x = 0; x < kBlockSide; ++x, p_c += step_x) {
      if (!(p_c.z() > 0.0f)) continue;
      const float inv_z = 1.0f / p_c.z();  // K.project with one division
      // Nearest pixel: floor(x + 0.5). The range test runs on the floats (it also rejects NaN and
      // coordinates too large for an int); on [0, size) the truncating conversion is the floor.
      const float uf = args.K.fx * p_c.x() * inv_z + args.K.cx + 0.5f;
      const float vf = args.K.fy * p_c.y() * inv_z + args.K.cy + 0.5f;
      if (!(uf >= 0.0f && vf >= 0.0f && uf < width && vf < height)) continue;
      const int u = int(uf), v = int(vf);
      const FusionPixel px = args.pixels(u, v);
      if (!(px.d > 0.0f)) continue;
      const Eigen::Vector3f P((float(u) - args.K.cx) * inv_fx * px.d, (float(v) - args.K.cy) * inv_fy * px.d, px.d);
      const Eigen::Vector3f dp = p_c - P;
      const float sdf = px.nx * dp.x() + px.ny * dp.y() + px.nz * dp.z();
      if (sdf < -args.truncation) continue;
      if (sdf < args.truncation && dp.squaredNorm() > args.truncation * args.truncation) continue;
      const float t = sdf >= args.truncation ? 1.0f : sdf * inv_trunc;
      const int64_t k = k0 + x;
      AttrVoxel& attr = args.attributes[k];
      const Eigen::Vector3f c = to_color(args.color(u, v));
      fuse_sdf_color(args.geometry[k], attr, t, c, args.max_weight);
      if (args.reflection && sdf < args.truncation) {
        const float m = args.mask(u, v) ? 1.0f : 0.0f;
        fuse_reflection(attr, c, m, canonical_plane(args.remap, args.plane_ids(u, v)), args.window);
      }
    }
  });
}

void fusion_pixels_cpu(const FusionPixelArgs& a);
void fusion_pixels_cuda(const FusionPixelArgs& a);
void integrate_cpu(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cpu(const IntegrateArgs<Rgb8>& a);
void integrate_cuda(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cuda(const IntegrateArgs<Rgb8>& a);

}  // namespace rrg::kernel
