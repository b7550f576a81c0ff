#!/usr/bin/env bash
# The main job on the built-in default: installs the Debian packages, builds `rrg` (and the browser
# viewer when npm is there), synthesizes the reflective `living_room` sequence (glossy floor, TV,
# glossy table; Kinect-like depth noise), then
#   1. runs the whole RRG-SLAM pipeline in process (`rrg run`: tracking, TSDF fusion, reflective
#      plane identification, Gaussian mapping) and prints the metrics table (ATE, PSNR/SSIM on
#      training and held-out views, PSNR on reflective pixels, mesh accuracy/completion) and timings;
#   2. runs the same frames through the reconstruction service: starts `rrg serve` on loopback,
#      streams the sequence with `rrg stream` (poses back, live ATE), fetches the Draco mesh and the
#      SPZ Gaussians over gRPC, prints the server's Prometheus metrics and the viewer's address.
# Runs on the CPU when there is no GPU (a short sequence at a 1 cm voxel so that it finishes in
# minutes there); on a GPU machine FRAMES=300 VOXEL=0.005 gives the paper's settings.
# Environment: OUT_DIR (default out), FRAMES (60), VOXEL (0.01), DEVICE (auto), MODE (both | run |
# service), SERVE=1 keeps the server running at the end (Ctrl-C stops it) to watch in a browser.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install_deps.sh
BUILD_DIR=${BUILD_DIR:-build}
# Configured as scripts/test.sh configures it (tests and benchmarks on, the project's defaults), so
# that the two scripts share build/ without flipping each other's options; only `rrg` is built here.
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRRG_BUILD_TESTS=ON \
  -DRRG_BUILD_BENCH=ON -DCMAKE_CUDA_ARCHITECTURES="${RRG_CUDA_ARCH:-90}" >/dev/null
cmake --build "$BUILD_DIR" -j "${JOBS:-2}" --target rrg
RRG="$BUILD_DIR/bin/rrg"
OUT=${OUT_DIR:-out}
FRAMES=${FRAMES:-60}
VOXEL=${VOXEL:-0.01}
DEVICE=${DEVICE:-auto}
MODE=${MODE:-both}
case "$MODE" in both | run | service) ;; *) echo "quickstart: MODE must be both, run or service, got '$MODE'" >&2; exit 2 ;; esac
SETTINGS=(--set tsdf.voxel_size="$VOXEL" --set tsdf.truncation="$(awk "BEGIN{print 4*$VOXEL}")")

"$RRG" devices
"$RRG" synth --preset living_room --frames "$FRAMES" --width 320 --height 240 --novel 8 --noise \
  --out "$OUT/living_room" --overwrite

if [ "$MODE" != service ]; then
  echo "== 1. the whole pipeline in process: rrg run"
  "$RRG" run --dataset "$OUT/living_room" --out "$OUT/living_room_run" --device "$DEVICE" "${SETTINGS[@]}" \
    --decomposition 0 --no-progress
  echo "quickstart: trajectory, mesh, Gaussians, renders and metrics in $OUT/living_room_run"
fi
[ "$MODE" = run ] && exit 0

echo "== 2. the same frames through the reconstruction service: rrg serve + rrg stream"
VIEWER_OK=0
if command -v npm > /dev/null; then
  if (cd web_viewer && { [ -f node_modules/.rrg-lock-stamp ] && cmp -s package-lock.json node_modules/.rrg-lock-stamp ||
        { npm ci --no-audit --no-fund --loglevel=error && cp package-lock.json node_modules/.rrg-lock-stamp; }; } &&
        npm run --silent build); then
    VIEWER_OK=1
  else
    echo "quickstart: building the browser viewer failed; the service runs without it" >&2
  fi
else
  echo "quickstart: npm not found, the service runs without the browser viewer (docs/viewer.md)" >&2
fi
SVC="$OUT/living_room_service"
rm -rf "$SVC" && mkdir -p "$SVC/snapshots"
ADMIN_KEY=$(od -An -N16 -tx1 /dev/urandom | tr -d ' \n')
RRG_ADMIN_KEY="$ADMIN_KEY" "$RRG" serve --address 127.0.0.1:0 --port-file "$SVC/grpc.port" --device "$DEVICE" \
  --http-port 0 --http-port-file "$SVC/http.port" --metrics-port 0 --metrics-port-file "$SVC/metrics.port" \
  --snapshot-dir "$SVC/snapshots" --name quickstart > "$SVC/server.log" 2>&1 &
SERVER_PID=$!
stop_server() { kill "$SERVER_PID" 2> /dev/null && wait "$SERVER_PID" 2> /dev/null || true; }
trap stop_server EXIT
for _ in $(seq 1 300); do
  [ -s "$SVC/grpc.port" ] && [ -s "$SVC/http.port" ] && [ -s "$SVC/metrics.port" ] && break
  kill -0 "$SERVER_PID" 2> /dev/null || { cat "$SVC/server.log" >&2; echo "quickstart: rrg serve exited" >&2; exit 1; }
  sleep 0.1
done
[ -s "$SVC/grpc.port" ] || { cat "$SVC/server.log" >&2; echo "quickstart: rrg serve did not start in 30 s" >&2; exit 1; }
SERVER="127.0.0.1:$(cat "$SVC/grpc.port")"
SESSION=living-room-$(od -An -N4 -tx1 /dev/urandom | tr -d ' \n')
export RRG_TOKEN="$ADMIN_KEY"  # the admin key works for every session (rrg mesh / gaussians / sessions)
"$RRG" stream --dataset "$OUT/living_room" --server "$SERVER" --session-id "$SESSION" --out "$SVC" \
  "${SETTINGS[@]}" --progress 0 | sed 's/token [0-9a-f]*/token (hidden)/'
"$RRG" mesh --server "$SERVER" --session "$SESSION" --out "$SVC/mesh.drc"
"$RRG" gaussians --server "$SERVER" --session "$SESSION" --out "$SVC/gaussians_base.spz"
"$RRG" gaussians --server "$SERVER" --session "$SESSION" --set reflection --out "$SVC/gaussians_reflection.spz"
"$RRG" eval ate --est "$SVC/trajectory.txt" --ref "$OUT/living_room/groundtruth.txt"
echo "server metrics (Prometheus text, http://127.0.0.1:$(cat "$SVC/metrics.port")/metrics):"
curl -fsS "http://127.0.0.1:$(cat "$SVC/metrics.port")/metrics" | grep -E '^rrg_' | grep -v '_bucket' | head -30 || true
VIEWER="http://127.0.0.1:$(cat "$SVC/http.port")/?session=$SESSION&token=$ADMIN_KEY"
if [ "$VIEWER_OK" = 1 ]; then echo "viewer: $VIEWER"; fi
echo "quickstart: streamed trajectory, mesh (Draco) and Gaussians (SPZ) in $SVC; server log $SVC/server.log"
if [ "${SERVE:-0}" = 1 ]; then
  echo "quickstart: serving until Ctrl-C (gRPC $SERVER)"
  wait "$SERVER_PID"
fi
