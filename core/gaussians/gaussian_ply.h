#pragma once
// Gaussians as the standard 3DGS PLY (binary little-endian, DESIGN.md §4), readable by common
// splat viewers: per vertex, float
//   x y z nx ny nz f_dc_0..2 f_rest_0..(3(K−1)−1) opacity scale_0..2 rot_0..3
// with logit opacity, log scale, rot = (w, x, y, z), normals 0, and f_rest channel-major as 3DGS
// writes it (f_rest_{c·(K−1) + k−1} = SH coefficient k of channel c). The SH degree follows from
// the number of f_rest properties. The reflection set adds `int plane_id` after rot_3, and its
// plane equations go in a small JSON beside the PLY (<file>.planes.json).
#include "core/gaussians/gaussian_set.h"
#include "core/gaussians/reflective_plane.h"

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace rrg {

// Writes atomically; plane ids are written when with_plane_ids.
void write_gaussian_ply(const std::filesystem::path& path, const GaussianHost& g, bool with_plane_ids = false);
// Reads a 3DGS PLY (binary little-endian; float or double properties; unknown properties skipped).
// plane_id is read when present, else 0. Throws std::runtime_error naming the file and the problem.
GaussianHost read_gaussian_ply(const std::filesystem::path& path);
// The PLY header write_gaussian_ply produces (for tests and viewers).
std::string gaussian_ply_header(size_t count, int sh_degree, bool with_plane_ids);

// The reflection set: PLY with plane ids + <path>.planes.json with the plane equations.
std::filesystem::path planes_json_path(const std::filesystem::path& ply);
void write_reflection_ply(const std::filesystem::path& path, const GaussianHost& g,
                          std::span<const ReflectivePlane> planes);
std::vector<ReflectivePlane> read_planes_json(const std::filesystem::path& path);

}  // namespace rrg
