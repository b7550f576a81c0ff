#pragma once
// The spatial hash of blocks: open addressing with linear probing over packed 64-bit block keys
// (voxel.h). Inserts claim a slot with atomic_cas, so one body is race-free on both back ends.
// Capacity is a power of two; the host grows it (rehash) between frames, never during a kernel.
#include "core/common/atomics.h"
#include "core/common/span.h"
#include "core/tsdf/voxel.h"

namespace rrg::kernel {

inline constexpr int kMaxProbe = 256;  // an insert that finds no slot within this many fails (and
                                       // the host grows the table and runs the pass again)

struct HashView {
  Span<uint64_t> keys;    // [capacity] block key or kEmptyKey
  Span<int32_t> values;   // [capacity] block index in the pool, -1 = empty or pending
};

// Home slot of a key: MurmurHash3's 64-bit finaliser, so that every key bit reaches the low bits
// the mask keeps. (A plain multiplicative hash only carries bits upwards: the earlier
// ((key · φ) >> 17) & mask never saw the x coordinate in key bits 42–62, so a row of blocks along
// x shared one home slot and a 5 × 5 × 3 m room averaged 65 probes per insert instead of 1.2 —
// tests/tsdf/voxel_hash_test.cpp.)
RRG_HD inline uint64_t hash_slot(uint64_t key, uint64_t mask) {
  key ^= key >> 33;
  key *= 0xff51afd7ed558ccdull;
  key ^= key >> 33;
  key *= 0xc4ceb9fe1a85ec53ull;
  key ^= key >> 33;
  return key & mask;
}

// Relaxed load of a slot that other threads may be claiming (a stale kEmptyKey only leads to a CAS).
RRG_HD inline uint64_t load_key(const uint64_t* p) {
#if defined(__CUDA_ARCH__)
  return *static_cast<const volatile uint64_t*>(p);
#else
  return __atomic_load_n(p, __ATOMIC_RELAXED);
#endif
}

// Block index of key, or -1 when absent (read-only kernels: no concurrent inserts).
RRG_HD inline int32_t hash_find(const HashView& h, uint64_t key) {
  const uint64_t mask = uint64_t(h.keys.size) - 1;
  uint64_t slot = hash_slot(key, mask);
  for (int probe = 0; probe < kMaxProbe; ++probe) {
    const uint64_t k = h.keys[int64_t(slot)];
    if (k == key) return h.values[int64_t(slot)];
    if (k == kEmptyKey) return -1;
    slot = (slot + 1) & mask;
  }
  return -1;
}

enum class InsertResult { Inserted, Found, Full };

// Finds or claims the slot of key; slot receives its position. Full after kMaxProbe probes.
RRG_HD inline InsertResult hash_insert(const HashView& h, uint64_t key, int64_t& slot_out) {
  const uint64_t mask = uint64_t(h.keys.size) - 1;
  uint64_t slot = hash_slot(key, mask);
  for (int probe = 0; probe < kMaxProbe; ++probe) {
    uint64_t* p = &h.keys[int64_t(slot)];
    uint64_t k = load_key(p);
    if (k == kEmptyKey) k = atomic_cas(p, kEmptyKey, key);
    if (k == kEmptyKey) {
      slot_out = int64_t(slot);
      return InsertResult::Inserted;
    }
    if (k == key) {
      slot_out = int64_t(slot);
      return InsertResult::Found;
    }
    slot = (slot + 1) & mask;
  }
  return InsertResult::Full;
}

}  // namespace rrg::kernel
