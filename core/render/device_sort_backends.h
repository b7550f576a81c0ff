#pragma once
// Back-end entry points of device_sort.h (internal).
#include "core/render/device_sort.h"

namespace rrg::kernel {

void sort_pairs_cpu(Span<uint64_t> keys, Span<int32_t> values, int end_bit, SortScratch& scratch);
void sort_pairs_cuda(Span<uint64_t> keys, Span<int32_t> values, int end_bit, SortScratch& scratch);
int64_t exclusive_scan_cpu(Span<const int32_t> counts, Span<int32_t> offsets);
int64_t exclusive_scan_cuda(Span<const int32_t> counts, Span<int32_t> offsets, SortScratch& scratch);

}  // namespace rrg::kernel
