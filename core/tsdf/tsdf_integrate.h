#pragma once
// Fusion of a posed RGB-D frame into the augmented TSDF (paper §4.1.4), on the volume's device.
// Every frame: SDF, weight and running-average colour. Identification frames (every N_p = 10)
// also pass a ReflectionObservation: then the Welford intensity statistics (μ, M_2, n), the
// reflection strength r and the plane id π of the voxels in the band |sdf| < ε are updated too.
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/tsdf/tsdf_volume.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <span>

namespace rrg {

struct ReflectionObservation {
  const DeviceImage<int32_t>* plane_ids = nullptr;        // I_k^g per pixel (global or local ids), 0 = none
  const DeviceImage<uint8_t>* reflection_mask = nullptr;  // predicted reflection mask, non-zero = 1
  std::span<const int32_t> plane_remap;                   // id -> canonical id (ids beyond: themselves)
  // The frame's exposure relative to the map (core/planes/exposure_gain.h): the Welford statistic
  // takes the intensity x_t / exposure_gain. 1 = as the frame is (the paper). Must be finite, > 0.
  float exposure_gain = 1.0f;
};

// Fuses depth (metres, 0 = invalid) and colour (float RGB [0,1] or 8-bit) seen by a camera with
// intrinsics K at pose T_wc. The point-to-plane sdf and the grazing test take their normals from
// normal_depth when given (the tracker's bilateral-filtered D_k, Tracker::normal_depth(): noisy
// depth at fine resolutions has noise for normals), from depth otherwise; the surface positions are
// always depth's. All images must be K's size and on the volume's device (throws
// std::invalid_argument naming the mismatch). Returns the number of blocks the frame touched.
int64_t integrate(TsdfVolume& volume, const DeviceImage<float>& depth, const DeviceImage<Color>& color,
                  const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                  const ReflectionObservation* reflection = nullptr,
                  const DeviceImage<float>* normal_depth = nullptr);
int64_t integrate(TsdfVolume& volume, const DeviceImage<float>& depth, const DeviceImage<Rgb8>& color,
                  const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                  const ReflectionObservation* reflection = nullptr,
                  const DeviceImage<float>* normal_depth = nullptr);

// uint16 plane labels (LabelImage, as files store them) -> the int32 image integrate() takes.
DeviceImage<int32_t> plane_ids_to_device(const LabelImage& labels, const Device& device);

// The farthest from the camera centre that fusing one frame of camera K touches a block: the
// rays through the image corners out to depth max_depth, the truncation band there, and half a
// block's diagonal. A streaming radius (TsdfVolume::stream_out) below it sends blocks in view out
// after each frame and brings them back with the next.
float view_reach(const Intrinsics& K, const TsdfParams& params);

}  // namespace rrg
