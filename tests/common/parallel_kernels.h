#pragma once
// Small kernels written once (parallel_kernels_impl.h) and run on either back end, to test the
// parallel layer itself. Dispatch on the device of the data, like every core algorithm.
#include "core/common/buffer.h"

#include <cstdint>

namespace rrg::test {

struct Moments {  // a non-trivial reduction value: count, sum, sum of squares, max
  int64_t count = 0;
  double sum = 0.0;
  double sum_sq = 0.0;
  float max = -1e30f;
};

// y[i] = a * x[i] + y[i]
void saxpy(float a, const Buffer<float>& x, Buffer<float>& y);
// Moments of the positive entries of x.
Moments positive_moments(const Buffer<float>& x);
// Sum of i for i in [0, n) as int64 on the given device (exactness check).
int64_t index_sum(int64_t n, const Device& device);

}  // namespace rrg::test
