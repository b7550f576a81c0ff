#pragma once
// A reflective plane of L_ref with its equation (world frame): n · x + d = 0, |n| = 1.
#include <Eigen/Core>

#include <cstdint>

namespace rrg {

struct ReflectivePlane {
  int32_t id = 0;                                     // canonical plane id (ℓ of its Gaussians)
  Eigen::Vector4f plane = Eigen::Vector4f::Zero();    // (n_x, n_y, n_z, d)
};

}  // namespace rrg
