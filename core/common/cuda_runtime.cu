#include "core/common/cuda_check.cuh"
#include "core/common/cuda_runtime.h"

namespace rrg::detail {

int cuda_runtime_device_count() {
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no driver / no device" error
    return 0;
  }
  return n;
}

std::string cuda_runtime_device_name(int index) {
  cudaDeviceProp prop{};
  RRG_CUDA_CHECK(cudaGetDeviceProperties(&prop, index));
  return prop.name;
}

void* cuda_malloc(size_t bytes, int device) {
  RRG_CUDA_CHECK(cudaSetDevice(device));
  void* ptr = nullptr;
  RRG_CUDA_CHECK(cudaMalloc(&ptr, bytes));
  return ptr;
}

void cuda_free(void* ptr, int device) noexcept {
  if (!ptr) return;
  cudaSetDevice(device);
  cudaFree(ptr);
}

void cuda_memcpy(void* dst, const void* src, size_t bytes) {
  RRG_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyDefault));
}

void cuda_memset_zero(void* ptr, size_t bytes, int device) {
  RRG_CUDA_CHECK(cudaSetDevice(device));
  RRG_CUDA_CHECK(cudaMemset(ptr, 0, bytes));
}

void cuda_synchronize(int device) {
  RRG_CUDA_CHECK(cudaSetDevice(device));
  RRG_CUDA_CHECK(cudaDeviceSynchronize());
}

}  // namespace rrg::detail
