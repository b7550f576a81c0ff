#include "core/gaussians/spz.h"

#include "core/io/atomic_file.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace rrg {

namespace {

constexpr uint32_t kMagic = 0x5053474e;  // "NGSP"
constexpr float kColorScale = 0.15f;
constexpr float kSqrt1_2 = 0.70710678118654752f;
constexpr int kFractionalBits = 12;

// Sign of each SH coefficient k >= 1 (3DGS basis) under (x, y, z) -> (x, -y, -z): (-1)^(deg_y + deg_z).
constexpr float kShFlipRdfRub[15] = {-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1};

uint8_t to_u8(float x) { return uint8_t(std::clamp(std::round(x), 0.0f, 255.0f)); }

uint8_t quantize_sh(float x, int bucket) {
  int q = int(std::round(x * 128.0f) + 128.0f);
  q = (q + bucket / 2) / bucket * bucket;
  return uint8_t(std::clamp(q, 0, 255));
}

std::vector<uint8_t> gzip(const std::vector<uint8_t>& raw) {
  z_stream s{};
  if (deflateInit2(&s, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 9, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("encode_spz: deflateInit2 failed");
  std::vector<uint8_t> out(deflateBound(&s, uLong(raw.size())) + 64);
  s.next_in = const_cast<Bytef*>(raw.data());
  s.avail_in = uInt(raw.size());
  s.next_out = out.data();
  s.avail_out = uInt(out.size());
  const int r = deflate(&s, Z_FINISH);
  const size_t written = out.size() - s.avail_out;
  deflateEnd(&s);
  if (r != Z_STREAM_END) throw std::runtime_error("encode_spz: deflate failed");
  out.resize(written);
  return out;
}

std::vector<uint8_t> gunzip(const std::vector<uint8_t>& gz) {
  z_stream s{};
  if (inflateInit2(&s, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("decode_spz: inflateInit2 failed");
  s.next_in = const_cast<Bytef*>(gz.data());
  s.avail_in = uInt(gz.size());
  std::vector<uint8_t> out;
  uint8_t buf[65536];
  int r = Z_OK;
  while (r != Z_STREAM_END) {
    s.next_out = buf;
    s.avail_out = sizeof(buf);
    r = inflate(&s, Z_NO_FLUSH);
    if (r != Z_OK && r != Z_STREAM_END) {
      inflateEnd(&s);
      throw std::runtime_error("decode_spz: not a valid gzip stream");
    }
    out.insert(out.end(), buf, buf + (sizeof(buf) - s.avail_out));
    if (r == Z_OK && s.avail_in == 0 && s.avail_out != 0) {
      inflateEnd(&s);
      throw std::runtime_error("decode_spz: truncated gzip stream");
    }
  }
  inflateEnd(&s);
  return out;
}

void put_u32(std::vector<uint8_t>& o, uint32_t v) {
  for (int b = 0; b < 4; ++b) o.push_back(uint8_t(v >> (8 * b)));
}

}  // namespace

std::vector<uint8_t> encode_spz(const GaussianHost& g, const SpzOptions& opt) {
  g.validate();
  const size_t n = g.size();
  const int K = g.sh_coeffs();
  const float fp[3] = {1.0f, opt.rdf_to_rub ? -1.0f : 1.0f, opt.rdf_to_rub ? -1.0f : 1.0f};
  std::vector<uint8_t> raw;
  raw.reserve(16 + n * (9 + 1 + 3 + 3 + 4 + 3 * size_t(K - 1)));
  put_u32(raw, kMagic);
  put_u32(raw, 3);
  put_u32(raw, uint32_t(n));
  raw.insert(raw.end(), {uint8_t(g.sh_degree), uint8_t(kFractionalBits), 0, 0});
  const float scale = float(1 << kFractionalBits);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const int32_t f = int32_t(std::round(fp[c] * g.means[i][c] * scale));
      raw.insert(raw.end(), {uint8_t(f & 0xff), uint8_t((f >> 8) & 0xff), uint8_t((f >> 16) & 0xff)});
    }
  for (size_t i = 0; i < n; ++i) raw.push_back(to_u8(255.0f / (1.0f + std::exp(-g.logit_opacities[i]))));
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) raw.push_back(to_u8(g.sh[i * K][c] * (kColorScale * 255.0f) + 0.5f * 255.0f));
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) raw.push_back(to_u8((g.log_scales[i][c] + 10.0f) * 16.0f));
  for (size_t i = 0; i < n; ++i) {
    // ours (w, x, y, z) -> SPZ (x, y, z, w)
    const Eigen::Vector4f w = g.quats[i];
    Eigen::Vector4f q(w[1], w[2], w[3], w[0]);
    q /= q.norm();
    q[1] *= fp[1];
    q[2] *= fp[2];
    int largest = 0;
    for (int j = 1; j < 4; ++j)
      if (std::abs(q[j]) > std::abs(q[largest])) largest = j;
    const uint32_t negate = q[largest] < 0;
    uint32_t comp = uint32_t(largest);
    for (int j = 0; j < 4; ++j) {
      if (j == largest) continue;
      const uint32_t neg = uint32_t(q[j] < 0) ^ negate;
      const uint32_t mag = uint32_t(511.0f * (std::abs(q[j]) / kSqrt1_2) + 0.5f);
      comp = (comp << 10) | (neg << 9) | std::min(mag, 511u);
    }
    put_u32(raw, comp);
  }
  for (size_t i = 0; i < n; ++i)
    for (int k = 1; k < K; ++k)
      for (int c = 0; c < 3; ++c) {
        const float f = opt.rdf_to_rub ? kShFlipRdfRub[k - 1] : 1.0f;
        raw.push_back(quantize_sh(f * g.sh[i * K + size_t(k)][c], k < 4 ? 8 : 16));
      }
  return gzip(raw);
}

GaussianHost decode_spz(const std::vector<uint8_t>& bytes, const SpzOptions& opt) {
  const std::vector<uint8_t> raw = gunzip(bytes);
  if (raw.size() < 16) throw std::runtime_error("decode_spz: stream shorter than the 16-byte header");
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, raw.data() + at, 4);
    return v;
  };
  if (u32(0) != kMagic) throw std::runtime_error("decode_spz: bad magic (not an SPZ stream)");
  const uint32_t version = u32(4);
  if (version != 2 && version != 3) throw std::runtime_error("decode_spz: unsupported version " + std::to_string(version));
  const size_t n = u32(8);
  const int degree = raw[12], frac = raw[13];
  if (degree > kMaxShDegree) throw std::runtime_error("decode_spz: SH degree " + std::to_string(degree) + " not supported");
  if (raw[14] & 0x2) throw std::runtime_error("decode_spz: SPZ extensions are not supported");
  GaussianHost g(degree);
  const int K = g.sh_coeffs();
  const size_t rot_bytes = version >= 3 ? 4 : 3;
  const size_t need = 16 + n * (9 + 1 + 3 + 3 + rot_bytes + 3 * size_t(K - 1));
  if (raw.size() < need) throw std::runtime_error("decode_spz: stream ends before its " + std::to_string(n) + " Gaussians");
  g.resize(n);
  const float fp[3] = {1.0f, opt.rdf_to_rub ? -1.0f : 1.0f, opt.rdf_to_rub ? -1.0f : 1.0f};
  const uint8_t* p = raw.data() + 16;
  const float inv = 1.0f / float(1 << frac);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c, p += 3) {
      int32_t f = int32_t(p[0]) | (int32_t(p[1]) << 8) | (int32_t(p[2]) << 16);
      if (f & 0x800000) f |= int32_t(0xff000000u);
      g.means[i][c] = fp[c] * float(f) * inv;
    }
  for (size_t i = 0; i < n; ++i, ++p) {
    const float a = float(*p) / 255.0f;
    g.logit_opacities[i] = std::log(a / (1.0f - a));
  }
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c, ++p) g.sh[i * K][c] = (float(*p) / 255.0f - 0.5f) / kColorScale;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c, ++p) g.log_scales[i][c] = float(*p) / 16.0f - 10.0f;
  for (size_t i = 0; i < n; ++i) {
    float q[4];  // x, y, z, w
    if (version >= 3) {
      uint32_t comp = uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
      p += 4;
      const int largest = int(comp >> 30);
      float sum = 0;
      for (int j = 3; j >= 0; --j) {
        if (j == largest) continue;
        const uint32_t mag = comp & 511u, neg = (comp >> 9) & 1u;
        comp >>= 10;
        q[j] = kSqrt1_2 * float(mag) / 511.0f * (neg ? -1.0f : 1.0f);
        sum += q[j] * q[j];
      }
      q[largest] = std::sqrt(std::max(0.0f, 1.0f - sum));
    } else {
      float s = 0;
      for (int j = 0; j < 3; ++j, ++p) {
        q[j] = float(*p) / 127.5f - 1.0f;
        s += q[j] * q[j];
      }
      q[3] = std::sqrt(std::max(0.0f, 1.0f - s));
    }
    g.quats[i] = {q[3], q[0], fp[1] * q[1], fp[2] * q[2]};
  }
  for (size_t i = 0; i < n; ++i)
    for (int k = 1; k < K; ++k)
      for (int c = 0; c < 3; ++c, ++p) {
        const float f = opt.rdf_to_rub ? kShFlipRdfRub[k - 1] : 1.0f;
        g.sh[i * K + size_t(k)][c] = f * (float(*p) - 128.0f) / 128.0f;
      }
  return g;
}

void write_spz(const std::filesystem::path& path, const GaussianHost& g, const SpzOptions& options) {
  const std::vector<uint8_t> bytes = encode_spz(g, options);
  io::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) throw std::runtime_error("write_spz: cannot write " + tmp.string());
  });
}

GaussianHost read_spz(const std::filesystem::path& path, const SpzOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("read_spz: cannot open " + path.string());
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return decode_spz(bytes, options);
}

}  // namespace rrg
