#pragma once
// RRG_HD marks per-element code that runs on both back ends: __host__ __device__ under nvcc,
// nothing under the host compiler. The only copy of each piece of math carries it.
#if defined(__CUDACC__)
#define RRG_HD __host__ __device__
#define RRG_DEVICE_CODE 1
#else
#define RRG_HD
#endif
