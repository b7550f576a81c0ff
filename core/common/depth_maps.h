#pragma once
// Input preprocessing (paper §4.1.1): from a depth map D_k, the local vertex map V_k^l and normal
// map N_k^l in the camera frame. Runs on the device the depth lives on (CPU or CUDA).
// Invalid pixels (no depth, or a neighbour without depth) get V = N = (0, 0, 0).
#include "core/common/buffer.h"
#include "core/common/camera.h"

#include <Eigen/Core>

namespace rrg {

struct VertexNormalMaps {
  DeviceImage<Eigen::Vector3f> vertices;  // V_k^l, metres, camera frame
  DeviceImage<Eigen::Vector3f> normals;   // N_k^l, unit, facing the camera
};

// Throws std::invalid_argument when the depth size differs from the intrinsics' size.
VertexNormalMaps compute_vertex_normal_maps(const DeviceImage<float>& depth, const Intrinsics& K);
// The same into `out`, reusing its images when they already have the depth's size and device.
void compute_vertex_normal_maps_into(VertexNormalMaps& out, const DeviceImage<float>& depth, const Intrinsics& K);

// The sensor's positions with smoothed normals: V from `depth`, N from the vertices of
// `normal_depth` (the bilateral-filtered D_k), 0 where `depth` has no value. A filter in pixel space
// moves surfaces by amounts that depend on the view (it rounds a crease over the same pixels at 1 m
// and at 4 m), so positions filtered frame by frame disagree between views; its normals are only
// tilted near the crease. docs/tracking.md "Positions from the sensor, normals from the filter".
// Throws std::invalid_argument when the two depths differ in size or device, or from K's size.
VertexNormalMaps compute_vertex_normal_maps(const DeviceImage<float>& depth, const DeviceImage<float>& normal_depth,
                                            const Intrinsics& K);
void compute_vertex_normal_maps_into(VertexNormalMaps& out, const DeviceImage<float>& depth,
                                     const DeviceImage<float>& normal_depth, const Intrinsics& K);

}  // namespace rrg
