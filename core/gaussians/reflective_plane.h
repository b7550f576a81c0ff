#pragma once
// A reflective plane of L_ref with its equation (world frame): n · x + d = 0, |n| = 1.
#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace rrg {

struct ReflectivePlane {
  int32_t id = 0;                                     // canonical plane id (ℓ of its Gaussians)
  Eigen::Vector4f plane = Eigen::Vector4f::Zero();    // (n_x, n_y, n_z, d)
};

// Each plane's equation scaled to a unit normal, by id. Throws std::invalid_argument naming `who`
// and the plane when a normal is zero.
inline std::unordered_map<int32_t, Eigen::Vector4f> unit_planes_by_id(std::span<const ReflectivePlane> planes,
                                                                      const char* who) {
  std::unordered_map<int32_t, Eigen::Vector4f> by_id;
  for (const ReflectivePlane& pl : planes) {
    const float len = pl.plane.head<3>().norm();
    if (!(len > 0)) throw std::invalid_argument(std::string(who) + ": plane " + std::to_string(pl.id) + " has a zero normal");
    by_id[pl.id] = pl.plane / len;
  }
  return by_id;
}

}  // namespace rrg
