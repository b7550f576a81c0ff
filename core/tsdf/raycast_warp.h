#pragma once
// A raycast's plane-id map I moved to a nearby camera without marching again: each hit (its world
// point V* and id) is projected into the new view and written to the pixels whose centres lie
// within one pixel of it on both axes (at most 2 x 2, so no cracks open where the surface is
// magnified up to twice; one pixel when it is within 10⁻³ px of a centre), the nearest hit winning
// each pixel. Tracking's mask needs I at the ICP
// pose, one frame's motion from the model raycast at T_{k−1} (docs/tracking.md). Pixels no hit
// reaches (disoccluded, or beyond the source's edge) hold 0, no plane. The same pose and
// intrinsics give the source's I back exactly. Runs on the device the raycast lives on.
#include "core/common/buffer.h"
#include "core/common/camera.h"
#include "core/tsdf/tsdf_raycast.h"

#include <Eigen/Geometry>

namespace rrg {

// `source` needs depth, vertices (RaycastOutputs::normals) and plane_ids (RaycastOutputs::reflection);
// throws std::invalid_argument otherwise. `out` is resized to K; `zbuffer` is scratch (one word per
// pixel of K), reused across calls.
void warp_plane_ids(const RaycastResult& source, const Intrinsics& K, const Eigen::Isometry3f& T_wc,
                    DeviceImage<int32_t>& out, Buffer<uint64_t>& zbuffer);

}  // namespace rrg
