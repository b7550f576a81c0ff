#!/usr/bin/env bash
# All tests: installs the Debian packages, builds in Release (CUDA back end included when nvcc is
# present, one GPU architecture to keep the build short), runs every test on the CPU back end (and
# on CUDA too when a GPU is visible). Usage: scripts/test.sh [extra ctest args]
# Environment: BUILD_DIR (default build), JOBS (default 2), RRG_CUDA_ARCH (default 90).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-2}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRRG_BUILD_TESTS=ON -DRRG_BUILD_BENCH=ON \
  -DCMAKE_CUDA_ARCHITECTURES="${RRG_CUDA_ARCH:-90}"
cmake --build "$BUILD_DIR" -j "$JOBS"
"$BUILD_DIR/bin/rrg" devices
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" "$@"
