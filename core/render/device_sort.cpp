#include "core/render/device_sort.h"

#include "core/common/dispatch.h"
#include "core/render/device_sort_backends.h"

#include <stdexcept>
#include <string>

namespace rrg {

void sort_pairs(Span<uint64_t> keys, Span<int32_t> values, int end_bit, const Device& device,
                SortScratch& scratch) {
  if (keys.size != values.size)
    throw std::invalid_argument("sort_pairs: " + std::to_string(keys.size) + " keys but " +
                                std::to_string(values.size) + " values");
  if (end_bit < 1 || end_bit > 64)
    throw std::invalid_argument("sort_pairs: end_bit " + std::to_string(end_bit) + " outside [1, 64]");
  if (keys.size <= 1) return;
  RRG_DISPATCH(device, kernel::sort_pairs_cpu(keys, values, end_bit, scratch),
               kernel::sort_pairs_cuda(keys, values, end_bit, scratch));
}

int64_t exclusive_scan(Span<const int32_t> counts, Span<int32_t> offsets, const Device& device,
                       SortScratch& scratch) {
  if (counts.size != offsets.size)
    throw std::invalid_argument("exclusive_scan: " + std::to_string(counts.size) + " counts but " +
                                std::to_string(offsets.size) + " offsets");
  if (counts.size == 0) return 0;
  int64_t total = 0;
  RRG_DISPATCH(device, total = kernel::exclusive_scan_cpu(counts, offsets),
               total = kernel::exclusive_scan_cuda(counts, offsets, scratch));
  return total;
}

int bits_for(uint64_t n) {
  int bits = 1;
  while (bits < 64 && (uint64_t{1} << bits) < n) ++bits;
  return bits;
}

}  // namespace rrg
