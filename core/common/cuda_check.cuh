#pragma once
// Checks a CUDA runtime call or a kernel launch and throws std::runtime_error with file and line.
// Only for .cu files.
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace rrg::detail {

inline void cuda_check(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string("CUDA error: ") + cudaGetErrorString(status) + " in " +
                             what + " at " + file + ":" + std::to_string(line));
}

}  // namespace rrg::detail

#define RRG_CUDA_CHECK(expr) ::rrg::detail::cuda_check((expr), #expr, __FILE__, __LINE__)
// After a <<<...>>> launch: launch-configuration errors surface here.
#define RRG_CUDA_CHECK_LAUNCH() ::rrg::detail::cuda_check(cudaGetLastError(), "kernel launch", __FILE__, __LINE__)
