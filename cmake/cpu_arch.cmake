# The CPU instruction set of the C++ code (RRG_CPU_ARCH, passed as -march=). On x86-64 it is
# x86-64-v3 by default: AVX2, FMA, BMI2, F16C, which every x86-64 server and desktop CPU since
# 2015 has (Intel Haswell, AMD Excavator / Zen). Today the compiler's own use of it gains little
# (the 300-frame living_room pipeline 2-4 %, bench/RESULTS.md 2026-12-03); it lets CPU kernels use
# 8-wide vectors and std::fma without a run-time dispatch. "" keeps the compiler's default (SSE2
# on x86-64); "native" tunes for the build machine. Programs check at start-up that the CPU has the level they were built
# for (core/cpu_check.cpp) and exit with a message rather than die on an illegal instruction.
# CUDA device code is not affected (CMAKE_CUDA_ARCHITECTURES).
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(_rrg_arch_default "x86-64-v3")
else()
  set(_rrg_arch_default "")
endif()
set(RRG_CPU_ARCH "${_rrg_arch_default}" CACHE STRING
    "CPU instruction set of the C++ code (-march=...); empty for the compiler's default")

if(RRG_CPU_ARCH)
  include(CheckCXXCompilerFlag)
  check_cxx_compiler_flag("-march=${RRG_CPU_ARCH}" RRG_CPU_ARCH_OK_${RRG_CPU_ARCH})
  if(NOT RRG_CPU_ARCH_OK_${RRG_CPU_ARCH})
    message(FATAL_ERROR "RRG_CPU_ARCH=${RRG_CPU_ARCH}: the C++ compiler does not accept -march=${RRG_CPU_ARCH}; "
                        "pick another or pass -DRRG_CPU_ARCH= for the compiler's default")
  endif()
  add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-march=${RRG_CPU_ARCH}>)
  # Eigen's fixed-size types keep the layout of the SSE2 baseline (16-byte alignment), which nvcc's
  # passes and Debian's libraries (OpenCV, Open3D) are built with; core/common/camera.h asserts it.
  add_compile_definitions($<$<COMPILE_LANGUAGE:CXX>:EIGEN_MAX_STATIC_ALIGN_BYTES=16>)
endif()

# -ffp-contract=off: no multiply-add is fused unless the code says so (std::fma). GCC otherwise fuses
# a*b + c wherever the target has FMA (x86-64-v3, AArch64) and as it sees fit, which depends on the
# context an inlined expression lands in: the same source line then rounds differently in two places
# (the renderer's backward recomputing the forward's falloffs, rasterize_schedule_test.cpp), and
# the CPU back end is the oracle. Results of an x86-64-v3 build still differ from the baseline
# build's in the last bits (probably Eigen's wider packets summing in another order), not between
# runs or thread counts of one build.
add_compile_options($<$<COMPILE_LANGUAGE:CXX>:-ffp-contract=off>)

# The start-up check, compiled for the baseline so that it can run on any CPU. Every program links
# it through rrg_common (INTERFACE_SOURCES are added to each consumer).
add_library(rrg_cpu_check OBJECT ${PROJECT_SOURCE_DIR}/core/cpu_check.cpp)
# The level checked: x86-64-v2 / v3 / v4 (other values, such as "native", are not checked).
set(RRG_CPU_LEVEL "")
if(RRG_CPU_ARCH MATCHES "^x86-64-v[234]$")
  set(RRG_CPU_LEVEL "${RRG_CPU_ARCH}")
endif()
target_compile_definitions(rrg_cpu_check PRIVATE RRG_CPU_LEVEL="${RRG_CPU_LEVEL}")
if(RRG_CPU_ARCH AND CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  target_compile_options(rrg_cpu_check PRIVATE -march=x86-64)  # the last -march wins
endif()
message(STATUS "RRG: C++ code built for -march=${RRG_CPU_ARCH} (empty: the compiler's default)")
