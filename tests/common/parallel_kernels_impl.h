#pragma once
#include "core/common/hd.h"
#include "tests/common/parallel_kernels.h"

namespace rrg::test::kernel {

template <class Backend>
void saxpy(Backend b, float a, Span<const float> x, Span<float> y) {
  parallel_for(b, x.size, [=] RRG_HD(int64_t i) { y[i] = a * x[i] + y[i]; });
}

struct CombineMoments {
  RRG_HD Moments operator()(const Moments& p, const Moments& q) const {
    return {p.count + q.count, p.sum + q.sum, p.sum_sq + q.sum_sq, p.max > q.max ? p.max : q.max};
  }
};

template <class Backend>
Moments positive_moments(Backend b, Span<const float> x) {
  return parallel_reduce(b, x.size, Moments{}, [=] RRG_HD(int64_t i) {
        const float v = x[i];
        return v > 0.0f ? Moments{1, double(v), double(v) * v, v} : Moments{};
      }, CombineMoments{});
}

struct Plus {
  RRG_HD int64_t operator()(int64_t a, int64_t b) const { return a + b; }
};

template <class Backend>
int64_t index_sum(Backend b, int64_t n) {
  return parallel_reduce(b, n, int64_t{0}, [] RRG_HD(int64_t i) { return i; }, Plus{});
}

void saxpy_cpu(float a, Span<const float> x, Span<float> y);
Moments positive_moments_cpu(Span<const float> x);
int64_t index_sum_cpu(int64_t n);
void saxpy_cuda(float a, Span<const float> x, Span<float> y);
Moments positive_moments_cuda(Span<const float> x);
int64_t index_sum_cuda(int64_t n);

}  // namespace rrg::test::kernel
