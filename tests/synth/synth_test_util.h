#pragma once
// Helpers shared by the core/synth tests: small hand-built scenes and camera poses.
#include "core/synth/scene_builder.h"

#include <Eigen/Geometry>

namespace rrg::synth::test {

// Camera at `eye` looking along unit `forward` with world z up (OpenCV camera axes).
inline Eigen::Isometry3f look_along(const Eigen::Vector3f& eye, const Eigen::Vector3f& forward) {
  const Eigen::Vector3f f = forward.normalized();
  Eigen::Vector3f right = f.cross(Eigen::Vector3f::UnitZ());
  if (right.norm() < 1e-6f) right = Eigen::Vector3f::UnitX();
  right.normalize();
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear().col(0) = right;
  T.linear().col(1) = f.cross(right);
  T.linear().col(2) = f;
  T.translation() = eye;
  return T;
}

// A matte flat-grey material with no texture detail worth mentioning.
inline Texture flat(const Color& c) { return Texture{TextureKind::Solid, c, c, c, 1.0f, 0.0f}; }

}  // namespace rrg::synth::test
