#pragma once
// Analytic test scenes for the TSDF tests: spheres, boxes and planes with exact signed distances
// and exact depth images rendered by ray intersection (no TSDF code involved).
#include "core/common/camera.h"
#include "core/common/image.h"

#include <Eigen/Geometry>

#include <vector>

namespace rrg::test {

struct Primitive {
  enum Kind { Sphere, Box, Plane } kind = Sphere;
  Eigen::Vector3f a = Eigen::Vector3f::Zero();  // sphere/box centre; plane normal (unit)
  Eigen::Vector3f b = Eigen::Vector3f::Zero();  // box half extents; x = sphere radius; x = plane offset (n·p = b)
};

struct Scene {
  std::vector<Primitive> primitives;
  float sdf(const Eigen::Vector3f& p) const;  // exact signed distance of the union (box: exact)
  // z-depth of the first hit through pixel (x, y), 0 for none.
  float depth_at(const Intrinsics& K, const Eigen::Isometry3f& T_wc, float x, float y) const;
  DepthImage render_depth(const Intrinsics& K, const Eigen::Isometry3f& T_wc) const;
};

Scene sphere_scene(const Eigen::Vector3f& centre, float radius);
// Camera at `eye` looking at `target` (OpenCV axes: z forward, y down, world up = -y... any up not
// parallel to the view direction).
Eigen::Isometry3f look_at(const Eigen::Vector3f& eye, const Eigen::Vector3f& target,
                          const Eigen::Vector3f& up = Eigen::Vector3f(0, -1, 0));
// 14 cameras at distance `dist` around a point: the 6 axis directions and the 8 diagonals.
std::vector<Eigen::Isometry3f> cameras_around(const Eigen::Vector3f& target, float dist);

}  // namespace rrg::test

#include "core/tsdf/tsdf_volume.h"

namespace rrg::test {

// Renders the scene from every pose (uniform colour) and integrates each frame.
void fuse_scene(TsdfVolume& volume, const Scene& scene, const Intrinsics& K,
                const std::vector<Eigen::Isometry3f>& poses, const Color& color = Color(0.5f, 0.5f, 0.5f));

// Every voxel of the volume with its world position (voxel centre) and decoded values, sorted by
// block coordinate: the flat form parity tests compare.
std::vector<float> flatten_voxels(const TsdfVolume& volume);

}  // namespace rrg::test
