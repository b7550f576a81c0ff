#pragma once
// The CUDA back end of the parallel layer: the same parallel_for / parallel_reduce signatures as
// parallel_for.h, tagged CudaBackend. Only for .cu files.
#include "core/common/cuda_check.cuh"
#include "core/common/hd.h"
#include "core/common/parallel_for.h"

#include <cub/block/block_reduce.cuh>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace rrg {

struct CudaBackend {
  cudaStream_t stream = nullptr;  // default stream unless a caller owns one
};

namespace detail {
inline constexpr int kBlock = 256;
inline constexpr int64_t kMaxBlocks = 4096;  // grid-stride beyond this

template <class F>
__global__ void parallel_for_kernel(int64_t n, F f) {
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += int64_t(blockDim.x) * gridDim.x)
    f(i);
}

template <class T, class Map, class Combine>
__global__ void parallel_reduce_kernel(int64_t n, T identity, Map map, Combine combine, T* partial) {
  using BlockReduce = cub::BlockReduce<T, kBlock>;
  __shared__ typename BlockReduce::TempStorage temp;
  T acc = identity;
  for (int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x; i < n;
       i += int64_t(blockDim.x) * gridDim.x)
    acc = combine(acc, map(i));
  T block = BlockReduce(temp).Reduce(acc, combine);
  if (threadIdx.x == 0) partial[blockIdx.x] = block;
}

inline int blocks_for(int64_t n) {
  return int(std::clamp<int64_t>((n + kBlock - 1) / kBlock, 1, kMaxBlocks));
}
}  // namespace detail

template <class F>
void parallel_for(CudaBackend backend, int64_t n, F f) {
  if (n <= 0) return;
  detail::parallel_for_kernel<<<detail::blocks_for(n), detail::kBlock, 0, backend.stream>>>(n, f);
  RRG_CUDA_CHECK_LAUNCH();
}

// Block-level CUB reductions, then the per-block partials combined on the host in block order
// (deterministic for a given n). Returns after the GPU work is done.
template <class T, class Map, class Combine>
T parallel_reduce(CudaBackend backend, int64_t n, T identity, Map map, Combine combine) {
  if (n <= 0) return identity;
  const int blocks = detail::blocks_for(n);
  T* partial_d = nullptr;
  RRG_CUDA_CHECK(cudaMallocAsync(&partial_d, sizeof(T) * blocks, backend.stream));
  detail::parallel_reduce_kernel<<<blocks, detail::kBlock, 0, backend.stream>>>(n, identity, map, combine, partial_d);
  RRG_CUDA_CHECK_LAUNCH();
  std::vector<T> partial(blocks);
  RRG_CUDA_CHECK(cudaMemcpyAsync(partial.data(), partial_d, sizeof(T) * blocks,
                                 cudaMemcpyDeviceToHost, backend.stream));
  RRG_CUDA_CHECK(cudaFreeAsync(partial_d, backend.stream));
  RRG_CUDA_CHECK(cudaStreamSynchronize(backend.stream));
  T result = identity;
  for (const T& p : partial) result = combine(result, p);
  return result;
}

}  // namespace rrg
