#pragma once
// Depth of the virtual (mirrored) scene behind reflective planes, from the TSDF: the planar
// symmetry the paper builds on (§3, "reflected content can be interpreted as virtual scene behind
// the plane"), used to place new reflection Gaussians where the mirrored surface is instead of the
// paper's 10 samples 2–8 m past the plane (densify.reflection_mirrored_depth).
//
// For a plane n·x + d = 0 (unit n), H = I − 2nnᵀ reflects directions. The mirrored camera has
// centre H t − 2 d n and rotation H R F (F = diag(−1, 1, 1) keeps it a rotation), with
// c_x' = W − 1 − c_x: its pixel (W − 1 − u, v) sees along the reflection of pixel (u, v)'s ray,
// and the depth it raycasts there is the depth, in the original camera, of the virtual point
// behind the plane. Back faces (the mirror's own wall seen from behind) are not surfaces to a
// TSDF raycast, so the first surface found is the real content in front of the mirror.
#include "core/common/image.h"
#include "core/common/camera.h"
#include "core/gaussians/reflective_plane.h"
#include "core/tsdf/tsdf_raycast.h"

#include <Eigen/Geometry>

#include <functional>
#include <span>

namespace rrg {

// The mirrored camera of (K, T_wc) about `plane` (n·x + d = 0, n need not be unit).
struct MirroredCamera {
  Intrinsics K;
  Eigen::Isometry3f T_wc = Eigen::Isometry3f::Identity();
};
MirroredCamera mirror_camera(const Intrinsics& K, const Eigen::Isometry3f& T_wc, const Eigen::Vector4f& plane);

// Per pixel of (K, T_wc): the depth (metres along the optical axis) of the virtual point seen in
// the reflective plane under the pixel (plane_ids), from a raycast of the mirrored camera; 0 where
// the pixel is on no listed plane, or the mirrored ray finds no surface. One raycast per listed
// plane that covers a pixel.
Image<float> mirrored_depth(const std::function<RaycastResult(const Intrinsics&, const Eigen::Isometry3f&)>& raycast,
                            const Intrinsics& K, const Eigen::Isometry3f& T_wc, const Image<int32_t>& plane_ids,
                            std::span<const ReflectivePlane> planes);

}  // namespace rrg
