#include "tests/common/atomics_kernels.h"

#include "core/common/buffer.h"
#include "core/common/dispatch.h"
#include "tests/common/atomics_kernels_impl.h"

namespace rrg::test {
namespace kernel {
void atomics_cpu(int64_t n, float* f, int32_t* s, int32_t* m, Span<uint64_t> t, int32_t* ins);
void atomics_cuda(int64_t n, float* f, int32_t* s, int32_t* m, Span<uint64_t> t, int32_t* ins);
}  // namespace kernel

AtomicsResult run_atomics(int64_t n, const Device& device) {
  Buffer<float> f = Buffer<float>::zeros(1, device);
  Buffer<int32_t> ints = Buffer<int32_t>::zeros(3, device);  // sum, max, inserted
  std::vector<uint64_t> empty(size_t(n / 2 + 7), kernel::kEmpty);
  Buffer<uint64_t> table = Buffer<uint64_t>::from_host(empty, device);
  int32_t* p = ints.data();
  RRG_DISPATCH(device, kernel::atomics_cpu(n, f.data(), p, p + 1, table.span(), p + 2),
               kernel::atomics_cuda(n, f.data(), p, p + 1, table.span(), p + 2));
  const auto iv = ints.to_host();
  return {f.to_host()[0], iv[0], iv[1], table.to_host(), iv[2]};
}

}  // namespace rrg::test
