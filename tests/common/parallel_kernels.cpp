#include "tests/common/parallel_kernels.h"

#include "core/common/dispatch.h"
#include "tests/common/parallel_kernels_impl.h"

namespace rrg::test {

void saxpy(float a, const Buffer<float>& x, Buffer<float>& y) {
  if (x.size() != y.size() || !(x.device() == y.device()))
    throw std::invalid_argument("saxpy: x and y differ in size or device");
  RRG_DISPATCH(x.device(), kernel::saxpy_cpu(a, x.span(), y.span()),
               kernel::saxpy_cuda(a, x.span(), y.span()));
}

Moments positive_moments(const Buffer<float>& x) {
  Moments m;
  RRG_DISPATCH(x.device(), m = kernel::positive_moments_cpu(x.span()),
               m = kernel::positive_moments_cuda(x.span()));
  return m;
}

int64_t index_sum(int64_t n, const Device& device) {
  int64_t s = 0;
  RRG_DISPATCH(device, s = kernel::index_sum_cpu(n), s = kernel::index_sum_cuda(n));
  return s;
}

}  // namespace rrg::test
