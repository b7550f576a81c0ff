# Decides whether the CUDA back end is built (RRG_WITH_CUDA) from RRG_CUDA = AUTO|ON|OFF.
# AUTO builds it whenever nvcc is found, so the CUDA code is compiled everywhere and cannot rot,
# even on machines (like CI) that have the toolkit but no GPU.
set(RRG_WITH_CUDA OFF)
string(TOUPPER "${RRG_CUDA}" _rrg_cuda)
if(NOT _rrg_cuda MATCHES "^(AUTO|ON|OFF)$")
  message(FATAL_ERROR "RRG_CUDA must be AUTO, ON or OFF (got '${RRG_CUDA}')")
endif()

if(NOT _rrg_cuda STREQUAL "OFF")
  if(NOT CMAKE_CUDA_COMPILER AND NOT DEFINED ENV{CUDACXX} AND EXISTS /usr/local/cuda/bin/nvcc)
    set(CMAKE_CUDA_COMPILER /usr/local/cuda/bin/nvcc)
  endif()
  include(CheckLanguage)
  check_language(CUDA)
  if(CMAKE_CUDA_COMPILER)
    if(NOT DEFINED CMAKE_CUDA_ARCHITECTURES)
      # Turing, Ampere, Ada, Hopper. CI builds one of them to save time.
      set(CMAKE_CUDA_ARCHITECTURES "75;86;89;90")
    endif()
    enable_language(CUDA)
    find_package(CUDAToolkit REQUIRED)
    # CMake 3.25 predates nvcc's C++20 support; tell it the flag (nvcc >= 12 accepts -std=c++20).
    set(CMAKE_CUDA20_STANDARD_COMPILE_OPTION "-std=c++20")
    set(CMAKE_CUDA20_EXTENSION_COMPILE_OPTION "-std=c++20")
    list(APPEND CMAKE_CUDA_COMPILE_FEATURES cuda_std_20)
    set(CMAKE_CUDA_STANDARD 20)
    set(CMAKE_CUDA_STANDARD_REQUIRED ON)
    # Extended lambdas let one [=] RRG_HD (int64_t i) body run on both back ends; 20012 and
    # 20011/20014 are Eigen's host/device annotation noise.
    set(CMAKE_CUDA_FLAGS "${CMAKE_CUDA_FLAGS} --extended-lambda --expt-relaxed-constexpr -diag-suppress=20012,20011,20014,20015 -Xcompiler=-fopenmp")
    set(RRG_WITH_CUDA ON)
  elseif(_rrg_cuda STREQUAL "ON")
    message(FATAL_ERROR "RRG_CUDA=ON but no CUDA compiler (nvcc) was found")
  else()
    message(STATUS "RRG: nvcc not found, building the CPU back end only")
  endif()
endif()
