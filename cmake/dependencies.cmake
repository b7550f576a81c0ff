# Every dependency is a Debian package; scripts/install_deps.sh installs them.
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(spdlog REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(yaml-cpp REQUIRED)  # session config files (libyaml-cpp-dev)
# OpenCV: only the module packages we use are installed (libopencv-{core,imgproc,imgcodecs,
# features2d}-dev); they ship no OpenCVConfig.cmake, so the parts are found directly.
find_path(OpenCV_INCLUDE_DIRS opencv2/core.hpp PATH_SUFFIXES opencv4 REQUIRED)
set(OpenCV_LIBS "")
foreach(_m core imgproc imgcodecs features2d)
  find_library(OpenCV_${_m}_LIBRARY opencv_${_m} REQUIRED)
  list(APPEND OpenCV_LIBS ${OpenCV_${_m}_LIBRARY})
endforeach()
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Threads REQUIRED)
find_package(zstd CONFIG REQUIRED)   # libzstd-dev: RVL+zstd depth (core/io/rvl)
find_package(draco CONFIG REQUIRED)  # libdraco-dev: Draco meshes (core/io/draco_mesh)
include(${CMAKE_CURRENT_LIST_DIR}/grpc.cmake)
