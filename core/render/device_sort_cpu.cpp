// CPU primitives: least-significant-digit radix sort with 8-bit digits (stable, like CUB's), digit
// passes whose digit is the same for every key skipped; a sequential exclusive scan.
#include "core/render/device_sort_backends.h"

#include <array>
#include <cstring>

namespace rrg::kernel {

namespace {
template <class T>
void ensure(Buffer<T>& b, int64_t n) {
  if (int64_t(b.size()) < n) b = Buffer<T>(size_t(n + n / 2), Device::cpu());
}
}  // namespace

void sort_pairs_cpu(Span<uint64_t> keys, Span<int32_t> values, int end_bit, SortScratch& scratch) {
  const int64_t n = keys.size;
  ensure(scratch.keys, n);
  ensure(scratch.values, n);
  uint64_t* k_in = keys.data;
  int32_t* v_in = values.data;
  uint64_t* k_out = scratch.keys.data();
  int32_t* v_out = scratch.values.data();
  for (int shift = 0; shift < end_bit; shift += 8) {
    std::array<int64_t, 257> hist{};
    for (int64_t i = 0; i < n; ++i) ++hist[((k_in[i] >> shift) & 0xff) + 1];
    bool trivial = false;
    for (int d = 1; d <= 256; ++d) trivial |= hist[d] == n;
    if (trivial) continue;
    for (int d = 1; d <= 256; ++d) hist[d] += hist[d - 1];
    for (int64_t i = 0; i < n; ++i) {
      const int64_t at = hist[(k_in[i] >> shift) & 0xff]++;
      k_out[at] = k_in[i];
      v_out[at] = v_in[i];
    }
    std::swap(k_in, k_out);
    std::swap(v_in, v_out);
  }
  if (k_in != keys.data) {
    std::memcpy(keys.data, k_in, size_t(n) * sizeof(uint64_t));
    std::memcpy(values.data, v_in, size_t(n) * sizeof(int32_t));
  }
}

int64_t exclusive_scan_cpu(Span<const int32_t> counts, Span<int32_t> offsets) {
  int64_t sum = 0;
  for (int64_t i = 0; i < counts.size; ++i) {
    offsets[i] = int32_t(sum);
    sum += counts[i];
  }
  return sum;
}

}  // namespace rrg::kernel
