#pragma once
// Shared by the Open3D side-by-side benches: wall-clock and process CPU time, and our intrinsics as
// Open3D's 3x3 Float64 tensor.
#include "core/common/camera.h"

#include <open3d/core/Tensor.h>

#include <chrono>
#include <ctime>

namespace rrg::bench {

// Wall-clock and process CPU time in milliseconds (all threads: on a shared machine the CPU time is
// the steadier measure of work, and with OMP_NUM_THREADS=1 both libraries run on one core).
struct Clock {
  double wall, cpu;
};
inline Clock now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return {std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count(),
          double(ts.tv_sec) * 1e3 + double(ts.tv_nsec) * 1e-6};
}

inline open3d::core::Tensor intrinsic_tensor(const Intrinsics& K) {
  return open3d::core::Tensor::Init<double>({{K.fx, 0, K.cx}, {0, K.fy, K.cy}, {0, 0, 1}});
}

}  // namespace rrg::bench
