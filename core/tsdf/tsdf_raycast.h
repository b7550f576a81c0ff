#pragma once
// TSDF raycasting for any pose, intrinsics and resolution (pass 1 of the renderer; the ICP target
// of tracking; the variance map of plane identification §4.1.3). Runs on the volume's device.
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/tsdf/tsdf_volume.h"

#include <Eigen/Geometry>

#include <span>

namespace rrg {

// What a raycast computes besides the depth D_t (always). Shading reads a hit's voxel attributes
// only for the outputs asked for, and the 24 voxels beyond its cell only for the normal: tracking
// needs the geometry (D_t, V*, N*) alone; the mapper, the identification and the tracking mask's
// reflection render need D_t and attributes but no V*, N*.
struct RaycastOutputs {
  bool color = true;       // C_t
  bool reflection = true;  // I, R_raw, R, C_var
  bool normals = true;     // V*, N* (tracking's ICP model); the normal is the costlier half of shading
  static constexpr RaycastOutputs all() { return {true, true, true}; }
  static constexpr RaycastOutputs geometry() { return {false, false, true}; }
};

// Every image asked for is K's size (the others are empty, 0 x 0); pixels without a surface hold 0.
struct RaycastResult {
  DeviceImage<float> depth;                // D_t: depth along the optical axis, metres
  DeviceImage<Eigen::Vector3f> vertices;   // V*: world frame
  DeviceImage<Eigen::Vector3f> normals;    // N*: world frame, unit, pointing out of the surface
  DeviceImage<Eigen::Vector3f> colors;     // C_t: trilinear c̄
  DeviceImage<int32_t> plane_ids;          // I: π of the nearest voxel through the remap table
  DeviceImage<float> reflection;           // R_raw: trilinear r over voxels with n > 0
  DeviceImage<uint8_t> reflection_mask;    // R = R_raw > 0.5
  DeviceImage<float> color_variance;       // C_var = Σ w_i σ_i² / (Σ w_i + ε) over voxels with n > 0
};

// Casts a ray through every pixel of a camera (K, T_wc) within [min_depth, max_depth] of the
// volume's params; plane ids go through plane_remap (id -> canonical id) as in fusion. Only blocks
// resident on the device are seen: blocks streamed out (TsdfVolume::stream_out) must be brought
// back with stream_in first. `outputs` picks the maps beyond the geometry (all by default). Range
// image, empty-space skipping and refinement: docs/tsdf.md.
RaycastResult raycast(const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                      std::span<const int32_t> plane_remap = {}, RaycastOutputs outputs = RaycastOutputs::all());

// The same into `out`, reusing its images where they already have the size needed (a loop that
// raycasts every frame, as tracking does, then allocates nothing after the first call).
void raycast_into(RaycastResult& out, const TsdfVolume& volume, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                  std::span<const int32_t> plane_remap = {}, RaycastOutputs outputs = RaycastOutputs::all());

}  // namespace rrg
