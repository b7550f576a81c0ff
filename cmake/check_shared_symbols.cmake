# A CTest script (tests/CMakeLists.txt, test `shared_symbols`): fails when an object compiled by nvcc
# (*.cu.o) and one compiled by the host compiler (*.cpp.o) both define the same weak symbol in
# namespace rrg. The linker keeps one of such a pair, so the CPU back end could run nvcc's host
# compilation of a shared per-element function (core/common/hd.h: RRG_TU_LOCAL).
#   cmake -DNM=<nm> -DOBJECTS=<a;b;...> -P check_shared_symbols.cmake
cmake_minimum_required(VERSION 3.16)
if(NOT NM OR NOT OBJECTS)
  message(FATAL_ERROR "check_shared_symbols: pass -DNM=<nm> and -DOBJECTS=<object files>")
endif()

function(weak_rrg_symbols out_var)
  set(_all "")
  foreach(_obj IN LISTS ARGN)
    execute_process(COMMAND ${NM} --defined-only ${_obj} OUTPUT_VARIABLE _out RESULT_VARIABLE _rc)
    if(NOT _rc EQUAL 0)
      message(FATAL_ERROR "check_shared_symbols: ${NM} failed on ${_obj}")
    endif()
    string(REPLACE "\n" ";" _lines "${_out}")
    foreach(_line IN LISTS _lines)
      # "<address> W <mangled name>": weak definitions of functions and members in namespace rrg
      # (_ZN3rrg..., _ZNK3rrg... for const members). Library templates merely instantiated with rrg
      # types (std::vector<rrg::...>) are not ours to keep apart and are not matched.
      if(_line MATCHES "^[0-9a-f]+ [WV] (_ZNK?3rrg.*)$")
        list(APPEND _all "${CMAKE_MATCH_1}")
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES _all)
  set(${out_var} "${_all}" PARENT_SCOPE)
endfunction()

set(_cu "")
set(_cpp "")
foreach(_obj IN LISTS OBJECTS)
  if(_obj MATCHES "\\.cu\\.o(bj)?$")
    list(APPEND _cu "${_obj}")
  elseif(_obj MATCHES "\\.cpp\\.o(bj)?$")
    list(APPEND _cpp "${_obj}")
  endif()
endforeach()
if(NOT _cu)
  message(STATUS "check_shared_symbols: no CUDA objects, nothing to compare")
  return()
endif()
weak_rrg_symbols(_cu_syms ${_cu})
weak_rrg_symbols(_cpp_syms ${_cpp})
set(_both "")
foreach(_s IN LISTS _cu_syms)
  # Symbols of the CUDA back end's own types (rrg::CudaBackend) exist only in .cu objects anyway.
  if(_s IN_LIST _cpp_syms)
    list(APPEND _both "${_s}")
  endif()
endforeach()
list(LENGTH _cu_syms _n_cu)
list(LENGTH _cpp_syms _n_cpp)
if(_both)
  list(JOIN _both "\n  " _pretty)
  message(FATAL_ERROR "check_shared_symbols: weak rrg symbols defined by both nvcc and host objects "
                      "(mark the function RRG_TU_LOCAL, core/common/hd.h; c++filt decodes them):\n  ${_pretty}")
endif()
message(STATUS "check_shared_symbols: ${_n_cu} weak rrg symbols in .cu objects, ${_n_cpp} in .cpp objects, none in both")
