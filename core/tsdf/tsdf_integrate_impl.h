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
  float voxel_size;
  TruncationBand band;                     // ε(d)
  int max_weight, window;
  Span<const int32_t> active;              // blocks touched by this frame
  Span<const uint64_t> block_keys;
  Span<TsdfVoxel> geometry;
  Span<AttrVoxel> attributes;
  Span<uint64_t> versions;
  uint64_t version;
  bool reflection;                         // identification frame: update μ, M_2, n, r, π
  float inv_exposure_gain;                 // 1 / ReflectionObservation::exposure_gain (Welford input)
  ImageView<const int32_t> plane_ids;      // I_k^g
  ImageView<const uint8_t> mask;           // predicted reflection mask
  Span<const int32_t> remap;               // plane id -> canonical id
};

// The camera-frame position of the first voxel of row `row` (y + 8 z) of block `block`.
template <class ColorT>
RRG_HD RRG_INLINE Eigen::Vector3f row_start(const IntegrateArgs<ColorT>& args, int32_t block, int row) {
  const Eigen::Vector3i g0 = block_coord(args.block_keys[block]) * int(kBlockSide) + Eigen::Vector3i(0, row & 7, row >> 3);
  return args.R_cw * (g0.cast<float>() * args.voxel_size) + args.t_cw;
}

// Voxel k observed at pixel (u, v) as f says: the running averages, and on identification frames
// inside the band the reflection attributes.
template <class ColorT>
RRG_HD RRG_INLINE void fuse_voxel(const IntegrateArgs<ColorT>& args, int64_t k, int u, int v, const VoxelFusion& f) {
  AttrVoxel& attr = args.attributes[k];
  const Eigen::Vector3f c = to_color(args.color(u, v));
  fuse_sdf_color(args.geometry[k], attr, f.t, c, args.max_weight);
  if (args.reflection && f.kind == VoxelFusion::kBand) {
    const float m = args.mask(u, v) ? 1.0f : 0.0f;
    fuse_reflection(attr, c * args.inv_exposure_gain, m, canonical_plane(args.remap, args.plane_ids(u, v)), args.window);
  }
}

// Every voxel of every active block. The voxel p projects to pixel u with depth D(u),
// surface point P = D(u) K^-1 [u, 1] and normal n (N_k^l); its signed distance is the
// point-to-plane sdf = n · (p − P), which stays a metric distance on oblique surfaces where the
// projective D(u) − z overestimates it by 1 / cos θ. Pixels without a normal (image border, next to
// a hole) or seen at grazing angles (cos θ < kMinCos) are not fused (FusionPixel). Inside the band
// the plane is trusted only within ε of P (|p − P| <= ε: its error is then at most ε² / 2ρ for a
// surface of curvature radius ρ); farther voxels that are not free space (sdf < ε) are left alone.
// Voxels with sdf < −ε are skipped; the others fuse min(1, sdf / ε) (voxel_pixel, voxel_fusion and
// fuse_voxel in tsdf_integrate_device.h). One work item per row of 8 voxels along x (a block has
// 64): the block's data is decoded once and the camera-frame position advances by one vector add
// per voxel. The CPU back end runs integrate_rows_cpu (tsdf_integrate_cpu.cpp) instead: the same
// pieces on the row's 8 voxels at once, with the same result (TsdfIntegrate.RowLanesMatchThePerVoxelLoop).
template <class Backend, class ColorT>
void integrate(Backend backend, const IntegrateArgs<ColorT>& a) {
  const IntegrateArgs<ColorT> args = a;
  const VoxelProjection vp = voxel_projection(a.K, a.pixels.width, a.pixels.height, a.band);
  const Eigen::Vector3f step_x = a.R_cw.col(0) * a.voxel_size;  // camera-frame step of one voxel in x
  parallel_for(backend, a.active.size * (kBlockVoxels / kBlockSide), [=] RRG_HD(int64_t item) {
    const int32_t block = args.active[item / (kBlockVoxels / kBlockSide)];
    const int row = int(item % (kBlockVoxels / kBlockSide));  // y + 8 z
    if (row == 0) args.versions[block] = args.version;
    Eigen::Vector3f p_c = row_start(args, block, row);
    const int64_t k0 = int64_t(block) * kBlockVoxels + int64_t(row) * kBlockSide;
    for (int x = 0; x < kBlockSide; ++x, p_c += step_x) {
      int u, v;
      if (!voxel_pixel(vp, p_c, u, v)) continue;
      const VoxelFusion f = voxel_fusion(vp, args.pixels(u, v), u, v, p_c);
      if (f.kind != VoxelFusion::kNone) fuse_voxel(args, k0 + x, u, v, f);
    }
  });
}

void fusion_pixels_cpu(const FusionPixelArgs& a);
void fusion_pixels_cuda(const FusionPixelArgs& a);
void integrate_cpu(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cpu(const IntegrateArgs<Rgb8>& a);
// The per-voxel loop above on the CPU (what CUDA runs): the reference of the row lanes' test.
void integrate_per_voxel_cpu(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_per_voxel_cpu(const IntegrateArgs<Rgb8>& a);
void integrate_cuda(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cuda(const IntegrateArgs<Rgb8>& a);

}  // namespace rrg::kernel
