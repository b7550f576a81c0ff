#include "core/common/memory.h"

#include "core/common/cuda_runtime.h"

#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>

namespace rrg::mem {

namespace {
constexpr size_t kHostAlignment = 64;  // cache line; also enough for any SIMD load

[[noreturn]] void no_cuda(const Device& device) {
  require_device(device);  // throws with the reason
  throw std::runtime_error("CUDA back end not compiled in");
}
}  // namespace

void* allocate(size_t bytes, const Device& device) {
  if (bytes == 0) return nullptr;
  if (device.is_cpu()) {
    void* p = std::aligned_alloc(kHostAlignment, (bytes + kHostAlignment - 1) / kHostAlignment * kHostAlignment);
    if (!p) throw std::bad_alloc();
    return p;
  }
#ifdef RRG_WITH_CUDA
  require_device(device);
  return detail::cuda_malloc(bytes, device.index);
#else
  no_cuda(device);
#endif
}

void release(void* ptr, const Device& device) noexcept {
  if (!ptr) return;
  if (device.is_cpu()) {
    std::free(ptr);
    return;
  }
#ifdef RRG_WITH_CUDA
  detail::cuda_free(ptr, device.index);
#endif
}

void copy(void* dst, const Device& dst_device, const void* src, const Device& src_device,
          size_t bytes) {
  if (bytes == 0) return;
  if (dst_device.is_cpu() && src_device.is_cpu()) {
    std::memcpy(dst, src, bytes);
    return;
  }
#ifdef RRG_WITH_CUDA
  detail::cuda_memcpy(dst, src, bytes);
#else
  no_cuda(dst_device.is_cuda() ? dst_device : src_device);
#endif
}

void fill_zero(void* ptr, size_t bytes, const Device& device) {
  if (bytes == 0) return;
  if (device.is_cpu()) {
    std::memset(ptr, 0, bytes);
    return;
  }
#ifdef RRG_WITH_CUDA
  detail::cuda_memset_zero(ptr, bytes, device.index);
#else
  no_cuda(device);
#endif
}

void synchronize(const Device& device) {
  if (device.is_cpu()) return;
#ifdef RRG_WITH_CUDA
  detail::cuda_synchronize(device.index);
#else
  no_cuda(device);
#endif
}

}  // namespace rrg::mem
