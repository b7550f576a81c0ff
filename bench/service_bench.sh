#!/usr/bin/env bash
# Service benchmark: pose round-trip latency (p50 / p99) on loopback and sustained frames/s for 1
# and 4 concurrent sessions. Starts `rrg serve` on a free loopback port, makes a synthetic
# sequence, runs `rrg stream --preload` lock-step (--window 1: latency = one frame's round trip)
# and pipelined (--window 4: throughput), then stops the server. Never run by ctest.
#
#   bench/service_bench.sh [BUILD_DIR=build] [DEVICE=cpu] [FRAMES=60] [WIDTH=320] [HEIGHT=240]
# Extra session config: SET="--set sync=true ..." in the environment.
set -euo pipefail
BUILD=${1:-build}; DEVICE=${2:-cpu}; FRAMES=${3:-60}; WIDTH=${4:-320}; HEIGHT=${5:-240}
RRG="$BUILD/bin/rrg"
WORK=$(mktemp -d /tmp/rrg-service-bench.XXXXXX)
SET=${SET:-}
cleanup() { [ -n "${SERVER_PID:-}" ] && kill -TERM "$SERVER_PID" 2>/dev/null; wait 2>/dev/null; rm -rf "$WORK"; }
trap cleanup EXIT

"$RRG" synth --preset mirror_room --frames "$FRAMES" --width "$WIDTH" --height "$HEIGHT" --novel 0 \
  --out "$WORK/seq" > /dev/null 2>&1
"$RRG" serve --address 127.0.0.1:0 --port-file "$WORK/port" --device "$DEVICE" > "$WORK/serve.log" 2>&1 &
SERVER_PID=$!
for _ in $(seq 100); do [ -s "$WORK/port" ] && break; sleep 0.1; done
ADDR="127.0.0.1:$(cat "$WORK/port")"
echo "# rrg service bench: device $DEVICE, mirror_room ${WIDTH}x${HEIGHT}, $FRAMES frames, $(nproc) cores, load $(cut -d' ' -f1 /proc/loadavg) ${SET}"
run() {  # sessions window label
  echo "## $3: $1 session(s), window $2"
  # shellcheck disable=SC2086
  "$RRG" stream --dataset "$WORK/seq" --server "$ADDR" --sessions "$1" --window "$2" --preload --close \
    --progress 0 $SET 2>/dev/null | grep -E "frames/s|ATE"
}
run 1 1 "latency (lock-step)"
run 1 4 "throughput"
run 4 1 "latency (lock-step)"
run 4 4 "throughput"
