#pragma once
// The per-pixel input of fusion (tsdf_integrate_impl.h), in its own header so that the volume can
// keep the frame's image of them between frames (TsdfVolume::FrameScratch).

namespace rrg::kernel {

// What fusion needs of a depth pixel: the surface normal n (camera frame, facing the camera) and
// the depth d; d = 0 where the pixel is not fused (depth outside [min, max], no normal because of
// the image border or a hole, or a grazing view, cos θ < kMinCos). Computed once per pixel so that
// the per-voxel test is one 16-byte load.
struct FusionPixel {  // plain floats: bitwise copyable between devices
  float nx = 0.0f, ny = 0.0f, nz = 0.0f, d = 0.0f;
};

}  // namespace rrg::kernel
