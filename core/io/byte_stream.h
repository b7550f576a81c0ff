#pragma once
// Little-endian binary serialisation for snapshot files: a growing writer and a bounds-checked
// reader whose every read throws std::runtime_error("<what>: truncated ...") instead of reading
// past the end. Plain trivially copyable values, strings and vectors of them.
#include <Eigen/Geometry>

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace rrg::io {

class ByteWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_string(const std::string& s) {
    put<uint64_t>(s.size());
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<uint64_t>(v.size());
    const auto* p = reinterpret_cast<const uint8_t*>(v.data());
    bytes_.insert(bytes_.end(), p, p + v.size() * sizeof(T));
  }
  void put_bytes(std::span<const uint8_t> b) {
    put<uint64_t>(b.size());
    bytes_.insert(bytes_.end(), b.begin(), b.end());
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  std::vector<uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<uint8_t> bytes_;
};

class ByteReader {
 public:
  ByteReader(std::span<const uint8_t> bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::string get_string() {
    const uint64_t n = count(1);
    std::string s(reinterpret_cast<const char*>(bytes_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  template <class T>
  std::vector<T> get_vector() {
    static_assert(std::is_trivially_copyable_v<T>);
    const uint64_t n = count(sizeof(T));
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), bytes_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
    return v;
  }
  std::span<const uint8_t> get_bytes() {
    const uint64_t n = count(1);
    auto s = bytes_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  size_t remaining() const { return bytes_.size() - pos_; }
  const std::string& what() const { return what_; }

 private:
  void need(uint64_t n) const {
    if (n > bytes_.size() - pos_)
      throw std::runtime_error(what_ + ": truncated (need " + std::to_string(n) + " bytes at offset " +
                               std::to_string(pos_) + ", " + std::to_string(bytes_.size() - pos_) + " left)");
  }
  uint64_t count(size_t elem) {
    const auto n = get<uint64_t>();
    if (elem && n > (bytes_.size() - pos_) / elem)
      throw std::runtime_error(what_ + ": truncated or corrupt (a length of " + std::to_string(n) + " at offset " +
                               std::to_string(pos_) + " runs past the end)");
    return n;
  }
  std::span<const uint8_t> bytes_;
  size_t pos_ = 0;
  std::string what_;
};

// A rigid pose as its top 3x4 block, row by row (12 floats): the layout every snapshot section uses.
inline void put_pose(ByteWriter& w, const Eigen::Isometry3f& T) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) w.put(T.matrix()(i, j));
}
inline Eigen::Isometry3f get_pose(ByteReader& r) {
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) T.matrix()(i, j) = r.get<float>();
  return T;
}

}  // namespace rrg::io
