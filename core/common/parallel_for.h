#pragma once
// The CPU back end of the parallel layer (DESIGN.md §3). An algorithm's body lives once in an
// *_impl.h templated on a back-end tag and calls parallel_for / parallel_reduce with that tag; the
// *_cpu.cpp instantiates it with CpuBackend, the *_cuda.cu with CudaBackend
// (parallel_for_cuda.cuh). Bodies are lambdas `[=] RRG_HD (int64_t i)` capturing views only.
#include "core/common/hd.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace rrg {

struct CpuBackend {};

// f(i) for every i in [0, n), on OpenMP threads.
template <class F>
void parallel_for(CpuBackend, int64_t n, F f) {
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) f(i);
}

// combine(map(0), ..., map(n-1)) starting from identity. Deterministic whatever the thread count:
// fixed chunks are reduced in index order, then the chunk results in chunk order.
// T must be trivially copyable; combine must be associative.
inline constexpr int64_t kReduceChunk = 4096;

template <class T, class Map, class Combine>
T parallel_reduce(CpuBackend, int64_t n, T identity, Map map, Combine combine) {
  if (n <= 0) return identity;
  const int64_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
  std::vector<T> partial(size_t(chunks), identity);
#pragma omp parallel for schedule(dynamic, 1)
  for (int64_t c = 0; c < chunks; ++c) {
    T acc = identity;
    const int64_t end = std::min(n, (c + 1) * kReduceChunk);
    for (int64_t i = c * kReduceChunk; i < end; ++i) acc = combine(acc, map(i));
    partial[size_t(c)] = acc;
  }
  T result = identity;
  for (const T& p : partial) result = combine(result, p);
  return result;
}

}  // namespace rrg
