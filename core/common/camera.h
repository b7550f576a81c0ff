#pragma once
// Pinhole camera intrinsics (OpenCV convention: x right, y down, z forward; pixel centres at
// integer coordinates) and the per-element projection math shared by host and device code.
#include "core/common/hd.h"

#include <Eigen/Core>
#include <string>

// One layout of Eigen's fixed-size types in every object: the C++ code is built with AVX2
// (RRG_CPU_ARCH, cmake/cpu_arch.cmake), nvcc's host and device passes and Debian's libraries
// without, and Eigen would align 32-byte types (Matrix4f, Vector4d, Isometry3f) to 32 with AVX and
// to 16 without, so a struct holding one would differ between a .cpp and a .cu (kernel arguments)
// or a library. EIGEN_MAX_STATIC_ALIGN_BYTES=16 (set for the C++ code by cmake/cpu_arch.cmake)
// keeps the 16 of the SSE2 baseline; AVX loads of them are then unaligned ones.
static_assert(alignof(Eigen::Matrix4f) == 16 && alignof(Eigen::Vector4d) == 16,
              "Eigen's static alignment differs from the SSE2 baseline: see cmake/cpu_arch.cmake");

namespace rrg {

struct Intrinsics {
  float fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;

  RRG_HD bool valid() const { return fx > 0 && fy > 0 && width > 0 && height > 0; }

  // Pixel (u, v) at depth z (metres, along the optical axis) -> point in the camera frame.
  RRG_HD Eigen::Vector3f unproject(float u, float v, float z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
  // Camera-frame point -> pixel (u, v). Caller checks p.z() > 0.
  RRG_HD Eigen::Vector2f project(const Eigen::Vector3f& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  // Same camera at another resolution (pyramids, previews): scales focal lengths and centre so
  // that pixel centres stay at integer coordinates.
  Intrinsics scaled(int new_width, int new_height) const {
    const float sx = float(new_width) / float(width), sy = float(new_height) / float(height);
    return {fx * sx, fy * sy, (cx + 0.5f) * sx - 0.5f, (cy + 0.5f) * sy - 0.5f, new_width, new_height};
  }
  std::string to_string() const;
};

}  // namespace rrg
