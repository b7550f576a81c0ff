#pragma once
// Contended atomics on every back end (see atomics_test.cpp).
#include "core/common/device.h"

#include <cstdint>
#include <vector>

namespace rrg::test {

struct AtomicsResult {
  float float_sum = 0;          // n additions of 0.5f to one float
  int32_t int_sum = 0;          // n additions of 1 to one int
  int32_t max = 0;              // max of i over [0, n)
  std::vector<uint64_t> table;  // n/4 distinct keys each inserted 4 times into an open-addressed table
  int32_t inserted = 0;         // number of first insertions (must equal the distinct keys)
};
AtomicsResult run_atomics(int64_t n, const Device& device);

}  // namespace rrg::test
