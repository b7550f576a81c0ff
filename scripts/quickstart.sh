#!/usr/bin/env bash
# The main job on the built-in default: installs the Debian packages, builds `rrg`, synthesizes the
# reflective `living_room` sequence and evaluates it. Later issues turn this into "start the server
# and stream the built-in scene through it". Output goes to out/ (or $OUT_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRRG_BUILD_TESTS=OFF \
  -DRRG_BUILD_BENCH=OFF -DCMAKE_CUDA_ARCHITECTURES="${RRG_CUDA_ARCH:-90}" >/dev/null
cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target rrg
RRG="$BUILD_DIR/bin/rrg"
OUT=${OUT_DIR:-out}/living_room

"$RRG" devices
"$RRG" synth --preset living_room --frames 300 --width 320 --height 240 --out "$OUT" --overwrite
"$RRG" dataset info "$OUT"
"$RRG" eval ate --est "$OUT/groundtruth.txt" --ref "$OUT/groundtruth.txt"
echo "quickstart: sequence, ground truth and novel views in $OUT"
