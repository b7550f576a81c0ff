// The parallel layer: the same kernel bodies give the same answers on every back end, reductions
// are exact for integers and deterministic for floats whatever the thread count.
#include "tests/common/parallel_kernels.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <bit>
#include <random>

namespace rrg::test {
namespace {

std::vector<float> random_values(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(-1.0f, 1.0f);
  std::vector<float> v(n);
  for (auto& x : v) x = dist(rng);
  return v;
}

TEST(ParallelFor, SaxpyMatchesTheFormulaAndAgreesAcrossDevices) {
  const auto x = random_values(100003, 1), y = random_values(100003, 2);
  const auto cpu = expect_device_parity<float>(
      [&](const Device& d) {
        Buffer<float> xb = Buffer<float>::from_host(x, d), yb = Buffer<float>::from_host(y, d);
        saxpy(2.5f, xb, yb);
        return yb.to_host();
      },
      1e-6);
  for (size_t i = 0; i < x.size(); i += 997) EXPECT_FLOAT_EQ(cpu[i], 2.5f * x[i] + y[i]);
}

TEST(ParallelReduce, IntegerSumIsExactOnEveryDevice) {
  for (const Device& d : available_devices()) {
    for (int64_t n : {int64_t{0}, int64_t{1}, int64_t{4097}, int64_t{3'000'001}}) {
      EXPECT_EQ(index_sum(n, d), n * (n - 1) / 2) << d.to_string() << " n=" << n;
    }
  }
}

TEST(ParallelReduce, StructReductionIsCorrectAndAgreesAcrossDevices) {
  const auto x = random_values(250001, 3);
  Moments ref;
  for (float v : x)
    if (v > 0) {
      ref.count++;
      ref.sum += v;
      ref.sum_sq += double(v) * v;
      ref.max = std::max(ref.max, v);
    }
  expect_device_parity<double>(
      [&](const Device& d) {
        const Moments m = positive_moments(Buffer<float>::from_host(x, d));
        EXPECT_EQ(m.count, ref.count);
        EXPECT_NEAR(m.sum, ref.sum, 1e-9 * ref.count);
        EXPECT_NEAR(m.sum_sq, ref.sum_sq, 1e-9 * ref.count);
        EXPECT_EQ(m.max, ref.max);
        return std::vector<double>{double(m.count), m.sum, m.sum_sq, m.max};
      },
      1e-9, 1e-12);
}

TEST(ParallelReduce, CpuResultIsBitwiseIndependentOfThreadCount) {
  const auto x = random_values(300007, 4);
  const Buffer<float> xb = Buffer<float>::from_host(x, Device::cpu());
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const Moments one = positive_moments(xb);
  omp_set_num_threads(std::max(2, saved));
  const Moments many = positive_moments(xb);
  omp_set_num_threads(saved);
  EXPECT_EQ(std::bit_cast<uint64_t>(one.sum), std::bit_cast<uint64_t>(many.sum));
  EXPECT_EQ(std::bit_cast<uint64_t>(one.sum_sq), std::bit_cast<uint64_t>(many.sum_sq));
}

}  // namespace
}  // namespace rrg::test
