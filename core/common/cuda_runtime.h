#pragma once
// Thin host-side wrappers over the CUDA runtime, implemented in cuda_runtime.cu and only present
// in CUDA builds. Everything else reaches CUDA through device.h, memory.h and the back-end tags.
#include <cstddef>
#include <string>

namespace rrg::detail {

#ifdef RRG_WITH_CUDA
int cuda_runtime_device_count();  // 0 (never throws) when there is no GPU or driver
std::string cuda_runtime_device_name(int index);
void* cuda_malloc(size_t bytes, int device);
void cuda_free(void* ptr, int device) noexcept;
// Copies between any two of host / device memory; kind is inferred by the runtime (UVA).
void cuda_memcpy(void* dst, const void* src, size_t bytes);
void cuda_memset_zero(void* ptr, size_t bytes, int device);
void cuda_synchronize(int device);
#endif

}  // namespace rrg::detail
