#pragma once
// Small generators shared by the eval tests: random rigid motions, a smooth camera path, squares.
#include "core/common/mesh.h"
#include "core/io/trajectory.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace rrg::eval::test {

// A uniformly random rotation (normalised Gaussian quaternion) and a translation in [-2, 2]³ m.
inline Eigen::Isometry3d random_rigid(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return T;
}

// n poses at `rate` Hz from t0: a Lissajous path over a few metres, the camera yawing and pitching.
inline io::Trajectory smooth_trajectory(size_t n, double rate = 30.0, double t0 = 1000.0) {
  io::Trajectory traj(n);
  for (size_t k = 0; k < n; ++k) {
    const double t = double(k) / rate;
    traj[k].timestamp = t0 + t;
    traj[k].T_wc.linear() = (Eigen::AngleAxisd(0.4 * t, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.2 * std::sin(0.7 * t), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
    traj[k].T_wc.translation() = Eigen::Vector3d(1.5 * std::sin(0.3 * t), 0.4 * std::sin(0.5 * t), 1.0 * std::cos(0.2 * t));
  }
  return traj;
}

// The square [x0, x0 + sx] × [y0, y0 + sy] at height z, two triangles, normal +z.
inline TriangleMesh square(double x0, double y0, double sx, double sy, double z) {
  TriangleMesh m;
  m.vertices = {Eigen::Vector3f(x0, y0, z), Eigen::Vector3f(x0 + sx, y0, z), Eigen::Vector3f(x0 + sx, y0 + sy, z),
                Eigen::Vector3f(x0, y0 + sy, z)};
  m.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 2, 3)};
  return m;
}

}  // namespace rrg::eval::test
