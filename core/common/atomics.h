#pragma once
// Atomic read-modify-write operations usable from RRG_HD per-element code on both back ends:
// CUDA atomics under nvcc's device pass, GCC __atomic builtins on the host (CPU back end threads).
// Hash-table insertion (TSDF block allocation) and gradient accumulation (renderer backward
// passes) go through these, so one body is race-free on both back ends.
#include "core/common/hd.h"

#include <cstdint>

namespace rrg {

// Compare-and-swap on a 64-bit word; returns the value found before the operation.
RRG_HD inline uint64_t atomic_cas(uint64_t* address, uint64_t expected, uint64_t desired) {
#if defined(__CUDA_ARCH__)
  return atomicCAS(reinterpret_cast<unsigned long long*>(address), (unsigned long long)expected,
                   (unsigned long long)desired);
#else
  __atomic_compare_exchange_n(address, &expected, desired, false, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE);
  return expected;  // on failure, holds the value found; on success, the old (== expected) value
#endif
}

RRG_HD inline int32_t atomic_cas(int32_t* address, int32_t expected, int32_t desired) {
#if defined(__CUDA_ARCH__)
  return atomicCAS(address, expected, desired);
#else
  __atomic_compare_exchange_n(address, &expected, desired, false, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE);
  return expected;
#endif
}

// Returns the old value.
RRG_HD inline int32_t atomic_add(int32_t* address, int32_t value) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(address, value);
#else
  return __atomic_fetch_add(address, value, __ATOMIC_ACQ_REL);
#endif
}

RRG_HD inline uint32_t atomic_add(uint32_t* address, uint32_t value) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(address, value);
#else
  return __atomic_fetch_add(address, value, __ATOMIC_ACQ_REL);
#endif
}

// Float add; returns the old value. On the CPU a CAS loop (GCC has no float fetch_add builtin).
RRG_HD inline float atomic_add(float* address, float value) {
#if defined(__CUDA_ARCH__)
  return atomicAdd(address, value);
#else
  float old;
  __atomic_load(address, &old, __ATOMIC_RELAXED);
  float desired;
  do {
    desired = old + value;
  } while (!__atomic_compare_exchange(address, &old, &desired, true, __ATOMIC_ACQ_REL, __ATOMIC_RELAXED));
  return old;
#endif
}

RRG_HD inline int32_t atomic_max(int32_t* address, int32_t value) {
#if defined(__CUDA_ARCH__)
  return atomicMax(address, value);
#else
  int32_t old = __atomic_load_n(address, __ATOMIC_RELAXED);
  while (old < value &&
         !__atomic_compare_exchange_n(address, &old, value, true, __ATOMIC_ACQ_REL, __ATOMIC_RELAXED)) {
  }
  return old;
#endif
}

// Unsigned 64-bit minimum; returns the old value. On the CPU a CAS loop.
RRG_HD inline uint64_t atomic_min(uint64_t* address, uint64_t value) {
#if defined(__CUDA_ARCH__)
  return atomicMin(reinterpret_cast<unsigned long long*>(address), (unsigned long long)value);
#else
  uint64_t old = __atomic_load_n(address, __ATOMIC_RELAXED);
  while (value < old &&
         !__atomic_compare_exchange_n(address, &old, value, true, __ATOMIC_ACQ_REL, __ATOMIC_RELAXED)) {
  }
  return old;
#endif
}

}  // namespace rrg
