#pragma once
// Chooses the back end from the device the data lives on. In builds without CUDA the CUDA branch
// is compiled out and asking for a CUDA device throws the reason (require_device).
//
//   RRG_DISPATCH(depth.device(), kernel::fuse_cpu(args...), kernel::fuse_cuda(args...));
//
// It expands to a statement (use it for calls that return void, or assign inside the branches).
#include "core/common/device.h"

#include <stdexcept>

#ifdef RRG_WITH_CUDA
#define RRG_DISPATCH(device, cpu_call, cuda_call) \
  do {                                            \
    if ((device).is_cpu()) {                      \
      cpu_call;                                   \
    } else {                                      \
      ::rrg::require_device(device);              \
      cuda_call;                                  \
    }                                             \
  } while (0)
#else
#define RRG_DISPATCH(device, cpu_call, cuda_call)                          \
  do {                                                                     \
    if ((device).is_cpu()) {                                               \
      cpu_call;                                                            \
    } else {                                                               \
      ::rrg::require_device(device);                                       \
      throw std::logic_error("CUDA requested in a build without CUDA");   \
    }                                                                      \
  } while (0)
#endif
