# Optional gRPC / Protobuf (Debian: libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev
# protobuf-compiler). When found, RRG_WITH_GRPC is ON and rrg_add_proto(<target> <files...>) turns
# proto/ files into a static library of generated C++ kept in the build folder. Without them the
# rest builds and the gRPC parts say at run time that the build has none.
set(RRG_WITH_GRPC OFF)
option(RRG_GRPC "Build the gRPC parts when gRPC is found" ON)
if(RRG_GRPC)
  find_package(Protobuf QUIET)
  find_package(gRPC CONFIG QUIET)  # Debian ships /usr/lib/x86_64-linux-gnu/cmake/grpc/gRPCConfig.cmake
  find_program(RRG_GRPC_CPP_PLUGIN grpc_cpp_plugin)
  if(Protobuf_FOUND AND Protobuf_PROTOC_EXECUTABLE AND RRG_GRPC_CPP_PLUGIN)
    if(TARGET gRPC::grpc++)
      set(RRG_GRPC_LIBS gRPC::grpc++)
    else()  # no CMake package: fall back to pkg-config
      find_package(PkgConfig QUIET)
      if(PkgConfig_FOUND)
        pkg_check_modules(RRG_GRPCPP QUIET IMPORTED_TARGET grpc++)
        if(RRG_GRPCPP_FOUND)
          set(RRG_GRPC_LIBS PkgConfig::RRG_GRPCPP)
        endif()
      endif()
    endif()
    if(RRG_GRPC_LIBS)
      set(RRG_WITH_GRPC ON)
    endif()
  endif()
endif()
if(RRG_WITH_GRPC)
  message(STATUS "RRG: gRPC found (${RRG_GRPC_CPP_PLUGIN})")
else()
  message(STATUS "RRG: gRPC not found, building without the gRPC parts (remote segmenter)")
endif()

# rrg_add_proto(<target> <proto files relative to proto/>): messages and services as a library.
function(rrg_add_proto target)
  set(_srcs "")
  set(_out ${CMAKE_BINARY_DIR}/proto_gen)
  foreach(_rel ${ARGN})
    get_filename_component(_dir ${_rel} DIRECTORY)
    get_filename_component(_name ${_rel} NAME_WE)
    set(_base ${_out}/${_dir}/${_name})
    add_custom_command(
      OUTPUT ${_base}.pb.cc ${_base}.pb.h ${_base}.grpc.pb.cc ${_base}.grpc.pb.h
      COMMAND ${CMAKE_COMMAND} -E make_directory ${_out}
      COMMAND ${Protobuf_PROTOC_EXECUTABLE} -I ${PROJECT_SOURCE_DIR}/proto --cpp_out=${_out}
              --grpc_out=${_out} --plugin=protoc-gen-grpc=${RRG_GRPC_CPP_PLUGIN} ${PROJECT_SOURCE_DIR}/proto/${_rel}
      DEPENDS ${PROJECT_SOURCE_DIR}/proto/${_rel}
      COMMENT "protoc ${_rel}")
    list(APPEND _srcs ${_base}.pb.cc ${_base}.grpc.pb.cc)
  endforeach()
  add_library(${target} STATIC ${_srcs})
  target_include_directories(${target} PUBLIC ${_out})
  target_link_libraries(${target} PUBLIC ${RRG_GRPC_LIBS} protobuf::libprotobuf)
endfunction()
