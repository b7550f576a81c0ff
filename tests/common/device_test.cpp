// The device layer: device selection, buffers and copies on every available device.
#include "core/common/buffer.h"
#include "core/common/device.h"
#include "tests/support/parity.h"

#include <gtest/gtest.h>

#include <numeric>

namespace rrg {
namespace {

TEST(Device, CpuIsAlwaysFirstAndParses) {
  const auto devices = available_devices();
  ASSERT_FALSE(devices.empty());
  EXPECT_TRUE(devices.front().is_cpu());
  EXPECT_EQ(parse_device("cpu"), Device::cpu());
  EXPECT_EQ(Device::cuda(1).to_string(), "cuda:1");
  EXPECT_EQ(parse_device("auto"), default_device());
}

TEST(Device, BadTextIsRejectedWithTheAcceptedForms) {
  try {
    parse_device("gpu");
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cpu, cuda, cuda:N"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_device("cuda:x"), std::invalid_argument);
}

TEST(Device, CudaWithoutAGpuSaysWhy) {
  if (cuda_device_count() > 0) {
    EXPECT_EQ(parse_device("cuda"), Device::cuda(0));
    EXPECT_THROW(parse_device("cuda:" + std::to_string(cuda_device_count())), std::runtime_error);
    return;
  }
  try {
    parse_device("cuda");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_TRUE(msg.find("no usable GPU") != std::string::npos ||
                msg.find("no CUDA back end") != std::string::npos)
        << msg;
  }
  EXPECT_EQ(default_device(), Device::cpu());
}

TEST(Buffer, RoundTripsAndCopiesOnEveryDevice) {
  std::vector<float> host(1000);
  std::iota(host.begin(), host.end(), 0.5f);
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    Buffer<float> b = Buffer<float>::from_host(host, device);
    EXPECT_EQ(b.size(), host.size());
    EXPECT_EQ(b.device(), device);
    EXPECT_EQ(b.to_host(), host);
    Buffer<float> c = b.copy_to(Device::cpu());
    EXPECT_EQ(c.to_host(), host);
    Buffer<float> z = Buffer<float>::zeros(17, device);
    EXPECT_EQ(z.to_host(), std::vector<float>(17, 0.0f));
  }
}

TEST(Buffer, MovesOwnershipAndRejectsSizeMismatch) {
  Buffer<int> a = Buffer<int>::from_host(std::vector<int>{1, 2, 3}, Device::cpu());
  const int* p = a.data();
  Buffer<int> b = std::move(a);
  EXPECT_EQ(b.data(), p);
  EXPECT_EQ(a.size(), 0u);  // NOLINT(bugprone-use-after-move): moved-from is empty by contract
  EXPECT_EQ(a.data(), nullptr);
  EXPECT_THROW(b.copy_from_host(std::vector<int>{1, 2}), std::invalid_argument);
  Buffer<int> empty(0, Device::cpu());
  EXPECT_TRUE(empty.to_host().empty());
}

TEST(DeviceImage, RoundTripsOnEveryDevice) {
  Image<uint16_t> img(7, 5);
  for (size_t i = 0; i < img.size(); ++i) img[i] = uint16_t(i * 31);
  for (const Device& device : available_devices()) {
    auto d = DeviceImage<uint16_t>::from_host(img, device);
    auto back = d.to_host();
    ASSERT_TRUE(back.same_size(img));
    EXPECT_TRUE(std::equal(back.pixels().begin(), back.pixels().end(), img.pixels().begin()));
  }
}

TEST(DeviceImage, UploadKeepsItsBufferForTheSameSize) {
  Image<uint16_t> a(7, 5), b(7, 5), c(4, 3);
  for (size_t i = 0; i < a.size(); ++i) a[i] = uint16_t(i * 31), b[i] = uint16_t(1000 - i);
  for (size_t i = 0; i < c.size(); ++i) c[i] = uint16_t(i + 7);
  auto equal = [](const Image<uint16_t>& x, const Image<uint16_t>& y) {
    return x.same_size(y) && std::equal(x.pixels().begin(), x.pixels().end(), y.pixels().begin());
  };
  for (const Device& device : available_devices()) {
    SCOPED_TRACE(device.to_string());
    DeviceImage<uint16_t> d;
    d.upload(a, device);
    EXPECT_TRUE(equal(d.to_host(), a));
    const uint16_t* kept = d.buffer().data();
    d.upload(b, device);  // same size: the same buffer, the new pixels
    EXPECT_EQ(d.buffer().data(), kept);
    EXPECT_TRUE(equal(d.to_host(), b));
    d.upload(c, device);  // another size
    EXPECT_EQ(d.width(), 4);
    EXPECT_TRUE(equal(d.to_host(), c));
  }
}

}  // namespace
}  // namespace rrg
