// CUDA primitives: cub::DeviceRadixSort::SortPairs (stable) and cub::DeviceScan::ExclusiveSum.
#include "core/common/cuda_check.cuh"
#include "core/render/device_sort_backends.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

namespace rrg::kernel {

namespace {
template <class T>
void ensure(Buffer<T>& b, int64_t n, const Device& device) {
  if (int64_t(b.size()) < n || b.device() != device) b = Buffer<T>(size_t(n + n / 2), device);
}
Device current_cuda() {
  int d = 0;
  RRG_CUDA_CHECK(cudaGetDevice(&d));
  return Device::cuda(d);
}
}  // namespace

void sort_pairs_cuda(Span<uint64_t> keys, Span<int32_t> values, int end_bit, SortScratch& scratch) {
  const int64_t n = keys.size;
  const Device dev = current_cuda();
  ensure(scratch.keys, n, dev);
  ensure(scratch.values, n, dev);
  cub::DoubleBuffer<uint64_t> k(keys.data, scratch.keys.data());
  cub::DoubleBuffer<int32_t> v(values.data, scratch.values.data());
  size_t temp_bytes = 0;
  RRG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, k, v, n, 0, end_bit));
  ensure(scratch.temp, int64_t(temp_bytes), dev);
  RRG_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(scratch.temp.data(), temp_bytes, k, v, n, 0, end_bit));
  if (k.Current() != keys.data) {
    RRG_CUDA_CHECK(cudaMemcpyAsync(keys.data, k.Current(), n * sizeof(uint64_t), cudaMemcpyDeviceToDevice));
    RRG_CUDA_CHECK(cudaMemcpyAsync(values.data, v.Current(), n * sizeof(int32_t), cudaMemcpyDeviceToDevice));
  }
  RRG_CUDA_CHECK(cudaStreamSynchronize(nullptr));
}

int64_t exclusive_scan_cuda(Span<const int32_t> counts, Span<int32_t> offsets, SortScratch& scratch) {
  const int64_t n = counts.size;
  const Device dev = current_cuda();
  size_t temp_bytes = 0;
  RRG_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, temp_bytes, counts.data, offsets.data, n));
  ensure(scratch.temp, int64_t(temp_bytes), dev);
  RRG_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(scratch.temp.data(), temp_bytes, counts.data, offsets.data, n));
  int32_t last[2] = {0, 0};
  RRG_CUDA_CHECK(cudaMemcpy(&last[0], offsets.data + n - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
  RRG_CUDA_CHECK(cudaMemcpy(&last[1], counts.data + n - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
  return int64_t(last[0]) + last[1];
}

}  // namespace rrg::kernel
