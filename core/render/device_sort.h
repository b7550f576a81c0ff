#pragma once
// The two GPU-specific primitives of tile binning behind one small interface each, on the device the
// data lives on: a stable key-value sort (CPU: LSD radix sort; CUDA: cub::DeviceRadixSort) and an
// exclusive prefix sum (CPU: a loop; CUDA: cub::DeviceScan). Both back ends give identical results.
#include "core/common/buffer.h"

#include <cstdint>

namespace rrg {

// Scratch memory the primitives reuse between calls (grown on demand, never shrunk).
struct SortScratch {
  Buffer<uint64_t> keys;
  Buffer<int32_t> values;
  Buffer<uint8_t> temp;
};

// Sorts (keys[i], values[i]) by keys ascending, stably, considering key bits [0, end_bit) only
// (higher bits must be zero). keys and values live on `device` and have the same size.
void sort_pairs(Span<uint64_t> keys, Span<int32_t> values, int end_bit, const Device& device,
                SortScratch& scratch);

// offsets[i] = sum_{j<i} counts[j]; returns the total sum (read back to the host).
int64_t exclusive_scan(Span<const int32_t> counts, Span<int32_t> offsets, const Device& device,
                       SortScratch& scratch);

// Bits needed to represent values in [0, n): at least 1.
int bits_for(uint64_t n);

}  // namespace rrg
