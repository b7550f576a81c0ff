#pragma once
// RRG_HD marks per-element code that runs on both back ends: __host__ __device__ under nvcc,
// nothing under the host compiler. The only copy of each piece of math carries it.
#if defined(__CUDACC__)
#define RRG_HD __host__ __device__
#define RRG_DEVICE_CODE 1
#else
#define RRG_HD
#endif

// RRG_TU_LOCAL: internal linkage (static) for a shared per-element function the host compiler may
// keep out of line (the ray march, the projection). An inline function with external linkage is one
// entity in the whole program: the g++ copy from a .cpp and nvcc's host copy from a .cu are both
// weak symbols, and the linker keeps one. The CPU back end then ran nvcc's host build of e.g.
// projection_terms, and its results depended on whether the CUDA back end was compiled in
// (2026-12-02). With static, each object file calls its own copy. The test `shared_symbols`
// (cmake/check_shared_symbols.cmake) fails when a .cu and a .cpp object define the same rrg symbol.
#define RRG_TU_LOCAL static

// RRG_INLINE: always inline a small per-sample helper into its (hot) caller. The host compiler's
// heuristics otherwise keep e.g. the trilinear sample of the ray march an out-of-line call whose
// results go through memory.
#if defined(__CUDACC__)
#define RRG_INLINE __forceinline__
#elif defined(__GNUC__)
#define RRG_INLINE inline __attribute__((always_inline))
#else
#define RRG_INLINE inline
#endif

// RRG_UNROLL: fully unroll a loop with a small constant trip count (per-voxel neighbourhood loops,
// whose array indices then become constants).
#if defined(__CUDACC__)
#define RRG_UNROLL _Pragma("unroll")
#elif defined(__GNUC__)
#define RRG_UNROLL _Pragma("GCC unroll 32")
#else
#define RRG_UNROLL
#endif

// RRG_PREFETCH(p): ask the CPU's caches for the line of p ahead of a read the code will do after
// other work (a hint: no effect on results). Nothing on the GPU, where the warp scheduler hides
// load latency by switching warps.
#if defined(__CUDA_ARCH__)
#define RRG_PREFETCH(p) ((void)0)
#elif defined(__GNUC__)
#define RRG_PREFETCH(p) __builtin_prefetch((p), 0, 3)
#else
#define RRG_PREFETCH(p) ((void)(p))
#endif
