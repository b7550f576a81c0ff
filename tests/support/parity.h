#pragma once
// Device parity: run one test body on every available device and compare each result with the
// CPU's (the oracle). Without a usable GPU the CUDA half is skipped, and the test says so.
#include "core/common/device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

namespace rrg::test {

// Says, once per process, why the CUDA half of parity tests is skipped (or that it runs).
void report_cuda_parity_status();

// body(device) -> flat vector of numbers. EXPECTs every non-CPU result to match the CPU result
// element-wise within abs_tol + rel_tol * |cpu|. NaNs must match NaNs. Returns the CPU result.
template <class T>
std::vector<T> expect_device_parity(const std::function<std::vector<T>(const Device&)>& body,
                                    double abs_tol, double rel_tol = 0.0) {
  report_cuda_parity_status();
  const std::vector<T> reference = body(Device::cpu());
  for (const Device& device : available_devices()) {
    if (device.is_cpu()) continue;
    SCOPED_TRACE("device " + device.to_string());
    const std::vector<T> got = body(device);
    EXPECT_EQ(got.size(), reference.size());
    size_t mismatches = 0;
    for (size_t i = 0; i < std::min(got.size(), reference.size()); ++i) {
      const double a = double(reference[i]), b = double(got[i]);
      const bool ok = (std::isnan(a) && std::isnan(b)) ||
                      std::abs(a - b) <= abs_tol + rel_tol * std::abs(a);
      if (!ok && mismatches++ < 5)
        ADD_FAILURE() << "element " << i << ": cpu " << a << " vs " << device.to_string() << " " << b;
    }
    EXPECT_EQ(mismatches, 0u) << "elements differing between cpu and " << device.to_string();
  }
  return reference;
}

}  // namespace rrg::test
