#pragma once
// The body of integrate() (tsdf_integrate.h), templated on the back-end tag and the colour type;
// instantiated by tsdf_integrate_cpu.cpp and tsdf_integrate_cuda.cu.
#include "core/common/camera.h"
#include "core/tsdf/tsdf_integrate_device.h"

namespace rrg::kernel {

template <class ColorT>
struct IntegrateArgs {
  ImageView<const float> depth;            // D_k, metres
  ImageView<const ColorT> color;           // C_k, registered to the depth
  ImageView<const Eigen::Vector3f> normals;  // N_k^l (camera frame, facing the camera), 0 = none
  Intrinsics K;
  Eigen::Matrix3f R_cw;                    // world -> camera
  Eigen::Vector3f t_cw;
  float voxel_size, truncation, min_depth, max_depth;
  int max_weight, window;
  Span<const int32_t> active;              // blocks touched by this frame
  Span<const uint64_t> block_keys;
  Span<Voxel> voxels;
  Span<uint64_t> versions;
  uint64_t version;
  bool reflection;                         // identification frame: update μ, M_2, n, r, π
  ImageView<const int32_t> plane_ids;      // I_k^g
  ImageView<const uint8_t> mask;           // predicted reflection mask
  Span<const int32_t> remap;               // plane id -> canonical id
};

// One thread per voxel of every active block. The voxel p projects to pixel u with depth D(u),
// surface point P = D(u) K^-1 [u, 1] and normal n (N_k^l); its signed distance is the
// point-to-plane sdf = n · (p − P), which stays a metric distance on oblique surfaces where the
// projective D(u) − z overestimates it by 1 / cos θ. Pixels without a normal (image border, next to
// a hole) or seen at grazing angles (cos θ < kMinCos) are not fused. Inside the band the plane
// is trusted only within ε of P (|p − P| <= ε: its error is then at most ε² / 2ρ for a surface of
// curvature radius ρ); farther voxels that are not free space (sdf < ε) are left alone. Voxels
// with sdf < −ε are skipped; the others fuse min(1, sdf / ε).
inline constexpr float kMinCos = 0.2f;

template <class Backend, class ColorT>
void integrate(Backend backend, const IntegrateArgs<ColorT>& a) {
  const IntegrateArgs<ColorT> args = a;
  parallel_for(backend, a.active.size * kBlockVoxels, [=] RRG_HD(int64_t i) {
    const int32_t block = args.active[i / kBlockVoxels];
    const int lv = int(i % kBlockVoxels);
    if (lv == 0) args.versions[block] = args.version;
    const Eigen::Vector3i g = block_coord(args.block_keys[block]) * int(kBlockSide) +
                              Eigen::Vector3i(lv & 7, (lv >> 3) & 7, lv >> 6);
    const Eigen::Vector3f p_c = args.R_cw * (g.cast<float>() * args.voxel_size) + args.t_cw;
    if (!(p_c.z() > 0.0f)) return;
    const Eigen::Vector2f uv = args.K.project(p_c);
    const int u = int(floorf(uv.x() + 0.5f)), v = int(floorf(uv.y() + 0.5f));
    if (!args.depth.contains(u, v)) return;
    const float d = args.depth(u, v);
    if (!(d >= args.min_depth && d <= args.max_depth)) return;
    const Eigen::Vector3f n = args.normals(u, v);
    const Eigen::Vector3f P = args.K.unproject(float(u), float(v), d);
    if (-n.dot(P) < kMinCos * P.norm()) return;  // no normal (n = 0) or grazing
    const float sdf = n.dot(p_c - P);
    if (sdf < -args.truncation) return;
    if (sdf < args.truncation && (p_c - P).squaredNorm() > args.truncation * args.truncation) return;
    const float t = sdf >= args.truncation ? 1.0f : sdf / args.truncation;
    Voxel& vox = args.voxels[int64_t(block) * kBlockVoxels + lv];
    const Eigen::Vector3f c = to_color(args.color(u, v));
    fuse_sdf_color(vox, t, c, args.max_weight);
    if (args.reflection && sdf < args.truncation) {
      const float m = args.mask(u, v) ? 1.0f : 0.0f;
      fuse_reflection(vox, c, m, canonical_plane(args.remap, args.plane_ids(u, v)), args.window);
    }
  });
}

void integrate_cpu(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cpu(const IntegrateArgs<Rgb8>& a);
void integrate_cuda(const IntegrateArgs<Eigen::Vector3f>& a);
void integrate_cuda(const IntegrateArgs<Rgb8>& a);

}  // namespace rrg::kernel
