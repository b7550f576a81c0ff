#!/usr/bin/env bash
# The main job on the built-in default: installs the Debian packages, builds `rrg`, synthesizes the
# reflective `living_room` sequence (glossy floor, TV, glossy table; Kinect-like depth noise) and runs
# the whole RRG-SLAM pipeline on it (tracking, TSDF fusion, reflective plane identification, Gaussian
# mapping), printing the metrics table (ATE, PSNR/SSIM on training and held-out views, PSNR on
# reflective pixels, geometry accuracy/completion) and per-stage timings. Runs on the CPU when there
# is no GPU (a short sequence at a 1 cm voxel so that it finishes in minutes there); on a GPU machine
# set FRAMES=300 VOXEL=0.005 for the paper's settings. Output goes to out/ (or $OUT_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRRG_BUILD_TESTS=OFF \
  -DRRG_BUILD_BENCH=OFF -DCMAKE_CUDA_ARCHITECTURES="${RRG_CUDA_ARCH:-90}" >/dev/null
cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target rrg
RRG="$BUILD_DIR/bin/rrg"
OUT=${OUT_DIR:-out}
FRAMES=${FRAMES:-60}
VOXEL=${VOXEL:-0.01}

"$RRG" devices
"$RRG" synth --preset living_room --frames "$FRAMES" --width 320 --height 240 --novel 8 --noise \
  --out "$OUT/living_room" --overwrite
"$RRG" run --dataset "$OUT/living_room" --out "$OUT/living_room_run" --device "${DEVICE:-auto}" \
  --set tsdf.voxel_size="$VOXEL" --set tsdf.truncation="$(awk "BEGIN{print 4*$VOXEL}")" \
  --decomposition 0 --no-progress
echo "quickstart: sequence in $OUT/living_room; trajectory, mesh, Gaussians, renders and metrics in $OUT/living_room_run"
