#!/usr/bin/env bash
# The tests under the compiler's sanitizers, CPU back end. Not part of CI: on the 2-core dev VM the
# ASan build takes ~45 min and its run ~30 min (docs/device.md "Sanitizers" has the figures).
#
#   scripts/sanitizers.sh asan   AddressSanitizer + UndefinedBehaviorSanitizer (leaks included) over
#                                every test program, in build-asan/; a report fails the run
#   scripts/sanitizers.sh tsan   ThreadSanitizer over the session tests, whose pre-mapping and
#                                mapping threads share the map (renders while mapping, the live and
#                                overlapped schedules, snapshots), in build-tsan/
#
# ThreadSanitizer cannot see the barriers of GCC's OpenMP runtime (libgomp is not instrumented), so
# the tsan run gives each thread's parallel loops one OpenMP thread (OMP_NUM_THREADS=1) and leaves
# out SessionTest.SyncModeIsDeterministic, which asks for three. The session's own threads and locks
# are what it checks. Environment: JOBS (default 2); for tsan, RRG_CLI (default build/bin/rrg, built
# when missing).
set -euo pipefail
cd "$(dirname "$0")/.."

kind=${1:-}
JOBS=${JOBS:-2}
case "$kind" in
  asan)
    dir=build-asan
    flags="-fsanitize=address,undefined -fno-omit-frame-pointer -g1"
    link="-fsanitize=address,undefined"
    extra=()
    ;;
  tsan)
    dir=build-tsan
    flags="-fsanitize=thread -g1"
    link="-fsanitize=thread"
    extra=(-DRRG_GRPC=OFF)
    ;;
  *)
    echo "usage: scripts/sanitizers.sh asan|tsan" >&2
    exit 2
    ;;
esac

scripts/install_deps.sh
cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DRRG_CUDA=OFF -DRRG_BUILD_TESTS=ON \
  -DRRG_BUILD_BENCH=OFF "${extra[@]}" -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="$link" -DCMAKE_SHARED_LINKER_FLAGS="$link"

failed=()
run() {  # name, command...: runs it, keeps its output in $dir/sanitizer-logs/name.log
  local name=$1
  shift
  mkdir -p "$dir/sanitizer-logs"
  local start=$SECONDS
  if "$@" > "$dir/sanitizer-logs/$name.log" 2>&1; then
    echo "$name: passed, no report ($((SECONDS - start)) s)"
  else
    echo "$name: FAILED or reported (exit $?, $((SECONDS - start)) s): $dir/sanitizer-logs/$name.log"
    failed+=("$name")
  fi
}

if [ "$kind" = asan ]; then
  cmake --build "$dir" -j "$JOBS"
  export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  for t in "$dir"/bin/test_*; do run "$(basename "$t")" "$t"; done
else
  cmake --build "$dir" -j "$JOBS" --target test_slam
  # the fixtures' `rrg synth` runs as a child process, outside the threads under test: the Release
  # build's (RRG_CLI overrides it)
  cli=${RRG_CLI:-$PWD/build/bin/rrg}
  if [ ! -x "$cli" ]; then
    cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
    cmake --build build -j "$JOBS" --target rrg
  fi
  export RRG_CLI=$cli
  supp=$(mktemp)
  trap 'rm -f "$supp"' EXIT
  # OpenCV's image reader takes GDAL's driver-manager locks in both orders (inside libgdal)
  echo "deadlock:libgdal.so" > "$supp"
  OMP_NUM_THREADS=1 TSAN_OPTIONS="suppressions=$supp" run test_slam-sessions "$dir/bin/test_slam" \
    --gtest_filter='SessionTest.*:SnapshotTest.*:-SessionTest.SyncModeIsDeterministic'
fi

if [ ${#failed[@]} -gt 0 ]; then
  echo "sanitizers ($kind): ${#failed[@]} failed: ${failed[*]}" >&2
  exit 1
fi
echo "sanitizers ($kind): all passed without a report"
