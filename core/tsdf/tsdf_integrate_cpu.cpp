#include "core/common/parallel_for.h"
#include "core/tsdf/tsdf_integrate_impl.h"

namespace rrg::kernel {

namespace {

// integrate() with the CPU's schedule: a work item is a row of 8 voxels along x, as there, but
// the voxel tests run on the whole row at once, in straight-line loops GCC vectorises (positions,
// then pixels; the pixels' fusion data gathered in between; then the fusion kinds), and only the
// voxels that fuse go through the scalar update. The positions advance by the same adds, in the
// same order, as the per-voxel loop's, so every voxel gets the same floats.
template <class ColorT>
void integrate_rows(const IntegrateArgs<ColorT>& a) {
  const IntegrateArgs<ColorT> args = a;
  const VoxelProjection vp = voxel_projection(a.K, a.pixels.width, a.pixels.height, a.band);
  const Eigen::Vector3f step_x = a.R_cw.col(0) * a.voxel_size;
  parallel_for(CpuBackend{}, a.active.size * (kBlockVoxels / kBlockSide), [&](int64_t item) {
    const int32_t block = args.active[item / (kBlockVoxels / kBlockSide)];
    const int row = int(item % (kBlockVoxels / kBlockSide));  // y + 8 z
    if (row == 0) args.versions[block] = args.version;
    float px_[kBlockSide], py_[kBlockSide], pz_[kBlockSide];
    Eigen::Vector3f p_c = row_start(args, block, row);
    for (int x = 0; x < kBlockSide; ++x, p_c += step_x) {
      px_[x] = p_c.x();
      py_[x] = p_c.y();
      pz_[x] = p_c.z();
    }
    int32_t u[kBlockSide], v[kBlockSide], seen[kBlockSide];
#pragma GCC ivdep
    for (int x = 0; x < kBlockSide; ++x) seen[x] = voxel_pixel(vp, Eigen::Vector3f(px_[x], py_[x], pz_[x]), u[x], v[x]);
    FusionPixel pix[kBlockSide];
    for (int x = 0; x < kBlockSide; ++x) pix[x] = seen[x] ? args.pixels(u[x], v[x]) : FusionPixel{};
    float t[kBlockSide];
    int32_t kind[kBlockSide];
#pragma GCC ivdep
    for (int x = 0; x < kBlockSide; ++x) {
      const VoxelFusion f = voxel_fusion(vp, pix[x], u[x], v[x], Eigen::Vector3f(px_[x], py_[x], pz_[x]));
      t[x] = f.t;
      kind[x] = f.kind;
    }
    const int64_t k0 = int64_t(block) * kBlockVoxels + int64_t(row) * kBlockSide;
    for (int x = 0; x < kBlockSide; ++x)
      if (kind[x] != VoxelFusion::kNone) fuse_voxel(args, k0 + x, u[x], v[x], VoxelFusion{t[x], kind[x]});
  });
}

}  // namespace

void fusion_pixels_cpu(const FusionPixelArgs& a) { fusion_pixels(CpuBackend{}, a); }
void integrate_cpu(const IntegrateArgs<Eigen::Vector3f>& a) { integrate_rows(a); }
void integrate_cpu(const IntegrateArgs<Rgb8>& a) { integrate_rows(a); }
void integrate_per_voxel_cpu(const IntegrateArgs<Eigen::Vector3f>& a) { integrate(CpuBackend{}, a); }
void integrate_per_voxel_cpu(const IntegrateArgs<Rgb8>& a) { integrate(CpuBackend{}, a); }

}  // namespace rrg::kernel
