#pragma once
// Buffer<T>: owning, move-only array of trivially copyable T on one device, with explicit copies.
// DeviceImage<T>: a Buffer with a width and height. Kernels never see these, only Span/ImageView.
#include "core/common/image.h"
#include "core/common/memory.h"
#include "core/common/span.h"

#include <Eigen/Core>

#include <algorithm>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

namespace rrg {

// Types whose bytes can be copied between devices: trivially copyable ones, and Eigen fixed-size
// matrices (plain arrays of scalars whose copy constructors are merely user-provided).
template <class T>
struct is_device_copyable : std::is_trivially_copyable<T> {};
template <class S, int R, int C, int O, int MR, int MC>
struct is_device_copyable<Eigen::Matrix<S, R, C, O, MR, MC>>
    : std::bool_constant<(R > 0 && C > 0 && std::is_trivially_copyable_v<S>)> {};

template <class T>
class Buffer {
  static_assert(is_device_copyable<T>::value, "Buffer<T> needs a bitwise-copyable T");

 public:
  Buffer() = default;
  Buffer(size_t count, const Device& device) : device_(device), size_(count) {
    data_ = static_cast<T*>(mem::allocate(count * sizeof(T), device));
  }
  static Buffer zeros(size_t count, const Device& device) {
    Buffer b(count, device);
    b.fill_zero();
    return b;
  }
  static Buffer from_host(std::span<const T> host, const Device& device) {
    Buffer b(host.size(), device);
    b.copy_from_host(host);
    return b;
  }
  ~Buffer() { mem::release(data_, device_); }

  Buffer(Buffer&& o) noexcept { swap(o); }
  Buffer& operator=(Buffer&& o) noexcept {
    Buffer tmp(std::move(o));
    swap(tmp);
    return *this;
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const Device& device() const { return device_; }
  Span<T> span() { return {data_, int64_t(size_)}; }
  Span<const T> span() const { return {data_, int64_t(size_)}; }

  void fill_zero() { mem::fill_zero(data_, size_ * sizeof(T), device_); }
  void copy_from_host(std::span<const T> host) {
    if (host.size() != size_)
      throw std::invalid_argument("Buffer::copy_from_host: size " + std::to_string(host.size()) +
                                  " != buffer size " + std::to_string(size_));
    mem::copy(data_, device_, host.data(), Device::cpu(), size_ * sizeof(T));
  }
  std::vector<T> to_host() const {
    std::vector<T> out(size_);
    mem::copy(out.data(), Device::cpu(), data_, device_, size_ * sizeof(T));
    return out;
  }
  Buffer copy_to(const Device& device) const {
    Buffer out(size_, device);
    mem::copy(out.data_, device, data_, device_, size_ * sizeof(T));
    return out;
  }

 private:
  void swap(Buffer& o) noexcept {
    std::swap(device_, o.device_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
  }
  Device device_ = Device::cpu();
  T* data_ = nullptr;
  size_t size_ = 0;
};

// The first n elements of b on the host (all of them when n >= b.size()).
template <class T>
std::vector<T> download_prefix(const Buffer<T>& b, int64_t n) {
  std::vector<T> out(size_t(std::clamp<int64_t>(n, 0, int64_t(b.size()))));
  if (!out.empty()) mem::copy(out.data(), Device::cpu(), b.data(), b.device(), out.size() * sizeof(T));
  return out;
}

template <class T>
class DeviceImage {
 public:
  DeviceImage() = default;
  DeviceImage(int width, int height, const Device& device)
      : width_(width), height_(height), buffer_(size_t(width) * size_t(height), device) {}
  static DeviceImage from_host(const Image<T>& image, const Device& device) {
    DeviceImage d(image.width(), image.height(), device);
    d.buffer_.copy_from_host(image.pixels());
    return d;
  }
  // from_host into this image, keeping its buffer when it has the size and device already (a loop
  // that uploads a frame every frame allocates only for the first).
  void upload(const Image<T>& image, const Device& device) {
    ensure(image.width(), image.height(), device);
    buffer_.copy_from_host(image.pixels());
  }
  Image<T> to_host() const {
    Image<T> out(width_, height_);
    mem::copy(out.data(), Device::cpu(), buffer_.data(), buffer_.device(), buffer_.size() * sizeof(T));
    return out;
  }

  // Gives the image the size width x height on device, keeping its buffer (and pixels) when it has
  // them already; loops that fill an image every frame call this instead of allocating anew.
  void ensure(int width, int height, const Device& device) {
    if (width_ != width || height_ != height || buffer_.device() != device) *this = DeviceImage(width, height, device);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  const Device& device() const { return buffer_.device(); }
  ImageView<T> view() { return {buffer_.data(), width_, height_}; }
  ImageView<const T> view() const { return {buffer_.data(), width_, height_}; }
  Buffer<T>& buffer() { return buffer_; }
  const Buffer<T>& buffer() const { return buffer_; }
  void fill_zero() { buffer_.fill_zero(); }

 private:
  int width_ = 0;
  int height_ = 0;
  Buffer<T> buffer_;
};

}  // namespace rrg
