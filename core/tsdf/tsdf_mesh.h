#pragma once
// Marching cubes on the TSDF (paper: mesh for evaluation and the viewer) with per-vertex colours
// and plane ids, on the volume's device. Each block owns the cubes whose lowest corner lies in it,
// so blocks can be meshed (and streamed) independently; whole-volume extraction welds the vertices
// that neighbouring blocks share on their faces. Cubes with an unobserved corner are skipped.
#include "core/common/mesh.h"
#include "core/tsdf/tsdf_volume.h"

#include <span>

namespace rrg {

// Every resident block, welded. Plane ids go through plane_remap (id -> canonical id).
TriangleMesh extract_mesh(const TsdfVolume& volume, std::span<const int32_t> plane_remap = {});

// The given resident blocks (others are ignored), welded among themselves: with
// volume.changed_blocks(v) this streams the part of the mesh changed since version v.
TriangleMesh extract_mesh(const TsdfVolume& volume, std::span<const Eigen::Vector3i> blocks,
                          std::span<const int32_t> plane_remap = {});

// Every block, resident or streamed out to host memory: the same mesh, byte for byte, as
// stream_in_all() then extract_mesh(), made in slabs of consecutive block x with no more than
// max_resident_blocks blocks resident at a time (more only where one slab of x and its +x
// neighbour layer hold more). Leaves resident the blocks that were resident before. For maps
// larger than the device (streaming, tsdf.md); without streamed-out blocks it is extract_mesh().
TriangleMesh extract_mesh_streamed(TsdfVolume& volume, int64_t max_resident_blocks,
                                   std::span<const int32_t> plane_remap = {});

}  // namespace rrg
