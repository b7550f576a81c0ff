// Contended atomics are exact on every back end and the CAS-based hash insert loses no key.
#include "tests/common/atomics_kernels.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace rrg::test {
namespace {

TEST(Atomics, ContendedUpdatesAreExactAndHashInsertIsRaceFree) {
  report_cuda_parity_status();
  const int64_t n = 200000;  // 0.5 * n is exact in float (100000 < 2^24)
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    const AtomicsResult r = run_atomics(n, device);
    EXPECT_EQ(r.float_sum, 0.5f * float(n));
    EXPECT_EQ(r.int_sum, n);
    EXPECT_EQ(r.max, n - 1);
    EXPECT_EQ(r.inserted, n / 4);
    std::vector<uint64_t> keys;
    for (uint64_t k : r.table)
      if (k != ~uint64_t{0}) keys.push_back(k);
    std::sort(keys.begin(), keys.end());
    ASSERT_EQ(keys.size(), size_t(n / 4));
    for (size_t i = 0; i < keys.size(); ++i) ASSERT_EQ(keys[i], i);
  }
}

}  // namespace
}  // namespace rrg::test
