#include "core/slam/snapshot_continuation.h"

#include "core/io/rvl.h"
#include "core/planes/plane_state_io.h"
#include "core/tracking/tracker_state_io.h"

#include <zstd.h>

#include <cstring>
#include <memory>
#include <stdexcept>

namespace rrg {
namespace {

constexpr uint32_t kSectionVersion = 3;  // 1: no fill regions, 2: no undecided planes (both still read)
constexpr int kZstdLevel = 3;

// raw size, then one zstd frame
template <class T>
void put_packed(io::ByteWriter& w, const std::vector<T>& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  const size_t raw = v.size() * sizeof(T);
  std::vector<uint8_t> out(ZSTD_compressBound(raw));
  const size_t n = ZSTD_compress(out.data(), out.size(), v.data(), raw, kZstdLevel);
  if (ZSTD_isError(n)) throw std::runtime_error(std::string("session snapshot: zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(n);
  w.put<uint64_t>(v.size());
  w.put_bytes(out);
}

template <class T>
std::vector<T> get_packed(io::ByteReader& r, const char* name) {
  const auto count = r.get<uint64_t>();
  const std::span<const uint8_t> z = r.get_bytes();
  // The frame states its content size: it must be the array's (the file is checksummed as a whole).
  const unsigned long long content = ZSTD_getFrameContentSize(z.data(), z.size());
  if (content == ZSTD_CONTENTSIZE_ERROR || content == ZSTD_CONTENTSIZE_UNKNOWN || count > content ||
      content != count * sizeof(T))
    throw std::runtime_error(r.what() + ": compressed array '" + name + "' is corrupt");
  std::vector<T> v(count);
  const size_t got = ZSTD_decompress(v.data(), count * sizeof(T), z.data(), z.size());
  if (ZSTD_isError(got) || got != count * sizeof(T))
    throw std::runtime_error(r.what() + ": compressed array '" + name + "' is corrupt");
  return v;
}

void put_frame(io::ByteWriter& w, const CompactFrame& f) {
  w.put<int64_t>(f.index);
  io::put_pose(w, f.T_wc);
  w.put<int32_t>(f.width), w.put<int32_t>(f.height);
  put_packed(w, f.rgb);
  w.put_bytes(io::encode_rvl_zstd(f.depth, f.width, f.height, kZstdLevel));
}

CompactFrame get_frame(io::ByteReader& r) {
  CompactFrame f;
  f.index = r.get<int64_t>();
  f.T_wc = io::get_pose(r);
  f.width = r.get<int32_t>(), f.height = r.get<int32_t>();
  if (f.width <= 0 || f.height <= 0 || f.width > 16384 || f.height > 16384)
    throw std::runtime_error(r.what() + ": frame " + std::to_string(f.index) + " has a bad size");
  f.rgb = get_packed<uint8_t>(r, "frame colour");
  if (f.rgb.size() != size_t(f.width) * size_t(f.height) * 3)
    throw std::runtime_error(r.what() + ": frame " + std::to_string(f.index) + " colour has the wrong length");
  try {
    f.depth = io::decode_rvl_zstd(r.get_bytes(), f.width, f.height);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(r.what() + ": frame " + std::to_string(f.index) + ": " + e.what());
  }
  return f;
}

// Floats as four byte planes (all lowest bytes, ..., all highest bytes): signs and exponents of
// neighbouring moments repeat, which zstd finds once they sit together.
std::vector<uint8_t> byte_planes(const std::vector<float>& f) {
  std::vector<uint8_t> out(f.size() * 4);
  for (size_t i = 0; i < f.size(); ++i) {
    uint8_t b[4];
    std::memcpy(b, &f[i], 4);
    for (int k = 0; k < 4; ++k) out[size_t(k) * f.size() + i] = b[k];
  }
  return out;
}

std::vector<float> from_byte_planes(const std::vector<uint8_t>& planes) {
  const size_t n = planes.size() / 4;
  std::vector<float> f(n);
  for (size_t i = 0; i < n; ++i) {
    uint8_t b[4];
    for (int k = 0; k < 4; ++k) b[k] = planes[size_t(k) * n + i];
    std::memcpy(&f[i], b, 4);
  }
  return f;
}

void put_adam(io::ByteWriter& w, const AdamStateHost& a) {
  w.put<int32_t>(a.stride);
  put_packed(w, byte_planes(a.m));
  put_packed(w, byte_planes(a.v));
  put_packed(w, a.steps);
}

AdamStateHost get_adam(io::ByteReader& r) {
  AdamStateHost a;
  a.stride = r.get<int32_t>();
  const auto m = get_packed<uint8_t>(r, "adam m"), v = get_packed<uint8_t>(r, "adam v");
  if (m.size() % 4 != 0 || v.size() % 4 != 0) throw std::runtime_error(r.what() + ": Adam moments are not whole floats");
  a.m = from_byte_planes(m);
  a.v = from_byte_planes(v);
  a.steps = get_packed<int32_t>(r, "adam steps");
  if (a.stride <= 0 || a.m.size() != a.steps.size() * size_t(a.stride) || a.v.size() != a.m.size())
    throw std::runtime_error(r.what() + ": Adam state lengths disagree");
  return a;
}

std::vector<CompactFrame> get_frames(io::ByteReader& r) {
  const auto n = r.get<uint64_t>();
  if (n > r.remaining()) throw std::runtime_error(r.what() + ": corrupt frame count");
  std::vector<CompactFrame> frames;
  for (uint64_t i = 0; i < n; ++i) frames.push_back(get_frame(r));
  return frames;
}

}  // namespace

std::vector<uint8_t> write_continuation(const ContinuationState& s) {
  if (s.pending.size() != s.pending_keyframe.size())
    throw std::invalid_argument("session snapshot: pending frames and keyframe flags differ in number");
  io::ByteWriter w;
  w.put<uint32_t>(kSectionVersion);
  write_tracker_state(w, s.tracker);
  w.put<uint64_t>(s.mapper.steps);
  w.put<uint64_t>(s.mapper.frames.size());
  for (const CompactFrame& f : s.mapper.frames) put_frame(w, f);
  w.put_vector(s.mapper.keyframes);
  w.put_vector(s.mapper.recent);
  put_adam(w, s.mapper.adam_base);
  put_adam(w, s.mapper.adam_reflection);
  w.put<uint64_t>(s.pending.size());
  for (const CompactFrame& f : s.pending) put_frame(w, f);
  w.put_vector(s.pending_keyframe);
  PlaneStateIo::write_fill_regions(w, s.fill_regions);
  w.put_vector(s.undecided_planes);
  return std::move(w.bytes());
}

ContinuationState read_continuation(std::span<const uint8_t> bytes, const std::string& what) {
  io::ByteReader r(bytes, what + " (continuation)");
  const auto version = r.get<uint32_t>();
  if (version < 1 || version > kSectionVersion)
    throw std::runtime_error(r.what() + ": unsupported section version " + std::to_string(version));
  ContinuationState s;
  s.tracker = read_tracker_state(r);
  s.mapper.steps = r.get<uint64_t>();
  s.mapper.frames = get_frames(r);
  s.mapper.keyframes = r.get_vector<uint32_t>();
  s.mapper.recent = r.get_vector<uint32_t>();
  for (const auto* ids : {&s.mapper.keyframes, &s.mapper.recent})
    for (const uint32_t i : *ids)
      if (i >= s.mapper.frames.size()) throw std::runtime_error(r.what() + ": frame reference out of range");
  s.mapper.adam_base = get_adam(r);
  s.mapper.adam_reflection = get_adam(r);
  s.pending = get_frames(r);
  s.pending_keyframe = r.get_vector<uint8_t>();
  if (s.pending_keyframe.size() != s.pending.size())
    throw std::runtime_error(r.what() + ": pending frames and keyframe flags differ in number");
  if (version >= 2) s.fill_regions = PlaneStateIo::read_fill_regions(r);
  if (version >= 3) s.undecided_planes = r.get_vector<int32_t>();
  if (r.remaining() != 0) throw std::runtime_error(r.what() + ": " + std::to_string(r.remaining()) + " trailing bytes");
  return s;
}

}  // namespace rrg
