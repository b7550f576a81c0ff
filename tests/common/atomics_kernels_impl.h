#pragma once
#include "core/common/atomics.h"
#include "core/common/span.h"

namespace rrg::test::kernel {

inline constexpr uint64_t kEmpty = ~uint64_t{0};

// Every thread adds to the same counters; keys k = i / 4 are inserted into an open-addressed table
// with linear probing: exactly one of the four inserters of a key may claim a slot.
template <class Backend>
void atomics(Backend b, int64_t n, float* fsum, int32_t* isum, int32_t* imax, Span<uint64_t> table,
             int32_t* inserted) {
  parallel_for(b, n, [=] RRG_HD(int64_t i) {
    atomic_add(fsum, 0.5f);
    atomic_add(isum, int32_t{1});
    atomic_max(imax, int32_t(i));
    const uint64_t key = uint64_t(i / 4);
    uint64_t slot = (key * 0x9E3779B97F4A7C15ull) % uint64_t(table.size);
    for (int64_t probe = 0; probe < table.size; ++probe) {
      const uint64_t found = atomic_cas(&table[int64_t(slot)], kEmpty, key);
      if (found == kEmpty) {
        atomic_add(inserted, int32_t{1});
        break;
      }
      if (found == key) break;
      slot = (slot + 1) % uint64_t(table.size);
    }
  });
}

}  // namespace rrg::test::kernel
