#pragma once
// Non-owning views that kernels take by value: a 1-D Span<T> and a 2-D row-major ImageView<T>.
// Plain structs usable on both back ends (std::span is not annotated for device code).
#include "core/common/hd.h"

#include <cstdint>
#include <type_traits>

namespace rrg {

template <class T>
struct Span {
  T* data = nullptr;
  int64_t size = 0;

  RRG_HD T& operator[](int64_t i) const { return data[i]; }
  RRG_HD bool empty() const { return size == 0; }
  RRG_HD operator Span<const T>() const
    requires(!std::is_const_v<T>)
  {
    return {data, size};
  }
};

template <class T>
struct ImageView {
  T* data = nullptr;
  int width = 0;
  int height = 0;

  RRG_HD T& operator()(int x, int y) const { return data[int64_t(y) * width + x]; }
  RRG_HD T& operator[](int64_t i) const { return data[i]; }
  RRG_HD int64_t size() const { return int64_t(width) * height; }
  RRG_HD bool contains(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  RRG_HD operator ImageView<const T>() const
    requires(!std::is_const_v<T>)
  {
    return {data, width, height};
  }
};

}  // namespace rrg
