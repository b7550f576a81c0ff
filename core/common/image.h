#pragma once
// Host images: a dense row-major grid of T with its width and height. Colours inside core are
// float RGB in [0,1] (Color); depth is float metres with 0 = invalid (DepthImage). 8-bit and
// 16-bit forms exist only at the edges (core/io/image_io.h).
#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace rrg {

using Color = Eigen::Vector3f;  // linear RGB in [0,1]

template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, const T& fill = T{}) : width_(width), height_(height) {
    if (width < 0 || height < 0) throw std::invalid_argument("Image: negative size");
    data_.assign(static_cast<size_t>(width) * static_cast<size_t>(height), fill);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }

  T& operator()(int x, int y) { return data_[static_cast<size_t>(y) * width_ + x]; }
  const T& operator()(int x, int y) const { return data_[static_cast<size_t>(y) * width_ + x]; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  // Views of the pixels. Not callable on a temporary image: `for (x : f().pixels())` would iterate
  // over freed memory (a bug this caught twice, both found only by the CUDA parity runs).
  std::span<T> pixels() & { return data_; }
  std::span<const T> pixels() const& { return data_; }
  void pixels() && = delete;

  template <class U>
  bool same_size(const Image<U>& o) const { return width_ == o.width() && height_ == o.height(); }

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<T> data_;
};

using ColorImage = Image<Color>;       // C: float RGB [0,1]
using DepthImage = Image<float>;       // D: metres, 0 = invalid
using MaskImage = Image<uint8_t>;      // 0 / 1
using LabelImage = Image<uint16_t>;    // semantic category or plane id, 0 = none

}  // namespace rrg
