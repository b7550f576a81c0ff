// The binning primitives behind their small interface: stable key-value sort and exclusive scan,
// known answers and CPU/CUDA parity (CUB on the GPU).
#include "core/render/device_sort.h"
#include "tests/support/parity.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <cstring>
#include <random>

namespace rrg::test {
namespace {

TEST(DeviceSort, SortsPairsStablyByTheLowKeyBits) {
  std::vector<uint64_t> keys = {5, 3, 5, 1, 0x100000003ull, 3};
  std::vector<int32_t> values = {0, 1, 2, 3, 4, 5};
  auto k = Buffer<uint64_t>::from_host(keys, Device::cpu());
  auto v = Buffer<int32_t>::from_host(values, Device::cpu());
  SortScratch scratch;
  sort_pairs(k.span(), v.span(), 33, Device::cpu(), scratch);
  EXPECT_EQ(k.to_host(), (std::vector<uint64_t>{1, 3, 3, 5, 5, 0x100000003ull}));
  EXPECT_EQ(v.to_host(), (std::vector<int32_t>{3, 1, 5, 0, 2, 4}));  // equal keys keep input order
}

TEST(DeviceSort, ScanReturnsOffsetsAndTotal) {
  const std::vector<int32_t> counts = {3, 0, 2, 5, 1};
  auto c = Buffer<int32_t>::from_host(counts, Device::cpu());
  Buffer<int32_t> o(counts.size(), Device::cpu());
  SortScratch scratch;
  EXPECT_EQ(exclusive_scan(c.span(), o.span(), Device::cpu(), scratch), 11);
  EXPECT_EQ(o.to_host(), (std::vector<int32_t>{0, 3, 3, 5, 10}));
}

TEST(DeviceSort, BadArgumentsAreNamed) {
  Buffer<uint64_t> k(4, Device::cpu());
  Buffer<int32_t> v(3, Device::cpu());
  SortScratch scratch;
  EXPECT_THROW(sort_pairs(k.span(), v.span(), 64, Device::cpu(), scratch), std::invalid_argument);
  Buffer<int32_t> v4(4, Device::cpu());
  EXPECT_THROW(sort_pairs(k.span(), v4.span(), 0, Device::cpu(), scratch), std::invalid_argument);
  EXPECT_EQ(bits_for(1), 1);
  EXPECT_EQ(bits_for(1200), 11);
  EXPECT_EQ(bits_for(2048), 11);
  EXPECT_EQ(bits_for(2049), 12);
}

// (tile, depth) keys as the binning writes them: 12 tile bits above 32 depth bits, many ties.
TEST(DeviceSort, SameOrderAsAStableSortOnEveryDevice) {
  std::mt19937 rng(4);
  const size_t n = 300000;
  std::vector<uint64_t> keys(n);
  std::uniform_int_distribution<uint64_t> tile(0, 3599);
  std::uniform_real_distribution<float> depth(0.1f, 8.0f);
  for (auto& k : keys) {
    float d = std::round(depth(rng) * 100) / 100;  // ties
    uint32_t bits;
    std::memcpy(&bits, &d, 4);
    k = (tile(rng) << 32) | bits;
  }
  std::vector<int32_t> expect(n);
  std::iota(expect.begin(), expect.end(), 0);
  std::stable_sort(expect.begin(), expect.end(), [&](int32_t a, int32_t b) { return keys[a] < keys[b]; });
  const auto got = expect_device_parity<int32_t>(
      [&](const Device& d) {
        auto k = Buffer<uint64_t>::from_host(keys, d);
        std::vector<int32_t> idx(n);
        std::iota(idx.begin(), idx.end(), 0);
        auto v = Buffer<int32_t>::from_host(idx, d);
        SortScratch scratch;
        sort_pairs(k.span(), v.span(), 44, d, scratch);
        return v.to_host();
      },
      0.0);
  EXPECT_EQ(got, expect);
}

TEST(DeviceSort, ScanParity) {
  std::mt19937 rng(9);
  std::vector<int32_t> counts(100000);
  for (auto& c : counts) c = int32_t(rng() % 20);
  const int64_t total = std::accumulate(counts.begin(), counts.end(), int64_t{0});
  expect_device_parity<int64_t>(
      [&](const Device& d) {
        auto c = Buffer<int32_t>::from_host(counts, d);
        Buffer<int32_t> o(counts.size(), d);
        SortScratch scratch;
        EXPECT_EQ(exclusive_scan(c.span(), o.span(), d, scratch), total);
        const auto off = o.to_host();
        return std::vector<int64_t>(off.begin(), off.end());
      },
      0.0);
}

// The CLI lists the same devices the render tests run on.
TEST(DeviceSort, CliDeviceListAgreesWithTheTestedDevices) {
  const CommandResult r = run_rrg("devices");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("cpu"), std::string::npos);
  for (const Device& d : available_devices())
    if (d.is_cuda()) EXPECT_NE(r.output.find(d.to_string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("default  : " + default_device().to_string()), std::string::npos) << r.output;
}

}  // namespace
}  // namespace rrg::test
