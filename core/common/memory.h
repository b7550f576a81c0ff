#pragma once
// Raw memory on a device: allocation, copies between any two devices, zero fill. Buffer<T>
// (buffer.h) is the owning, typed form everything else uses.
#include "core/common/device.h"

#include <cstddef>

namespace rrg::mem {

void* allocate(size_t bytes, const Device& device);             // throws on failure
void release(void* ptr, const Device& device) noexcept;
void copy(void* dst, const Device& dst_device, const void* src, const Device& src_device,
          size_t bytes);                                        // synchronous
void fill_zero(void* ptr, size_t bytes, const Device& device);
void synchronize(const Device& device);                          // waits for queued GPU work

}  // namespace rrg::mem
