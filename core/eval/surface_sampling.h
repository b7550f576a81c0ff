#pragma once
// Uniform random points on a mesh surface, as trimesh.sample.sample_surface (used by NICE-SLAM's
// mesh evaluation): a triangle is picked with probability ∝ its area, then a point uniformly inside
// it (p = (1 − √r1)·a + √r1·(1 − r2)·b + √r1·r2·c). Deterministic for a given seed on every
// platform (SplitMix64 stream, no std:: distributions).
#include "core/common/mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace rrg::eval {

// Total area of the mesh's triangles, m².
double surface_area(const TriangleMesh& mesh);

// n points uniformly by area. A mesh without triangles (a point cloud), or whose triangles have
// zero total area, yields its vertices instead (all of them, n is ignored). Throws
// std::invalid_argument when the mesh has no vertices or fails validate().
std::vector<Eigen::Vector3f> sample_surface(const TriangleMesh& mesh, size_t n, uint64_t seed);

// The same points (same seed, same stream) with the unit normal of the triangle each lies on, on
// the side its winding gives (right hand: (b − a) × (c − a)), i.e. the outward side of a closed or
// consistently wound mesh. A point cloud yields its vertices and no normals (normals empty).
struct OrientedSamples {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;  // [points.size()] or empty
};
OrientedSamples sample_surface_oriented(const TriangleMesh& mesh, size_t n, uint64_t seed);

}  // namespace rrg::eval
