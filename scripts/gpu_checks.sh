#!/usr/bin/env bash
# The CUDA checks of a lent GPU session (../shared/GPU.md), prepared so that one device call does
# them all within its few minutes.
#
#   scripts/gpu_checks.sh bundle   here: pack the test binaries and benchmarks of build/ (built with
#                                  -DCMAKE_CUDA_ARCHITECTURES=90 -DRRG_BUILD_BENCH=ON) into .gpu/
#   scripts/gpu_checks.sh device   there, in one `run` call with carry=[".gpu"]:
#                                    run(command="scripts/gpu_checks.sh device", carry=[".gpu"], timeout_s=540)
#
# On the device, in order of importance, each step under its own time limit so a slow one cannot
# starve the rest: the CUDA parity tests of the TSDF, renderer, Gaussians, tracking, planes and the
# session; the CUDA micro-benchmarks; compute-sanitizer on the TSDF tests. Logs go to $OUT/*.txt and
# a one-line verdict per step to $OUT/summary.txt (and stdout).
set -uo pipefail
cd "$(dirname "$0")/.."

tests=(test_tsdf test_render test_gaussians test_tracking test_planes test_common test_slam)
benches=(rrg_bench)

case "${1:-}" in
  bundle)
    exes=()
    for t in "${tests[@]}" "${benches[@]}"; do
      [[ -x build/bin/$t ]] || { echo "gpu_checks: build/bin/$t is missing (build with tests and benchmarks first)" >&2; exit 2; }
      exes+=("build/bin/$t")
    done
    ../shared/tools/gpu-bundle -o .gpu "${exes[@]}"
    ls -l .gpu/bundle.tar.xz
    ;;
  device)
    : "${OUT:?gpu_checks: device mode writes under \$OUT (the device tool sets it)}"
    [[ -f .gpu/bundle.tar.xz ]] || { echo "gpu_checks: .gpu/bundle.tar.xz not carried" >&2; exit 2; }
    g=/tmp/g
    mkdir -p "$g" && tar -C "$g" -xJf .gpu/bundle.tar.xz || exit 2
    export LD_LIBRARY_PATH=$g/lib PATH=$g/bin:$PATH
    nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader | tee "$OUT/device.txt"
    step() {  # step NAME SECONDS COMMAND...
      local name=$1 limit=$2
      shift 2
      local t0=$SECONDS
      timeout "$limit" "$@" > "$OUT/$name.txt" 2>&1
      local rc=$?
      local verdict="ok"
      ((rc == 124)) && verdict="TIMED OUT after ${limit}s"
      ((rc != 0 && rc != 124)) && verdict="FAILED (rc $rc)"
      echo "$name: $verdict, $((SECONDS - t0)) s" | tee -a "$OUT/summary.txt"
      grep -E "^\[  FAILED  \]" "$OUT/$name.txt" | head -20 | tee -a "$OUT/summary.txt"
    }
    step test_tsdf 60 test_tsdf --gtest_brief=1
    step test_render 60 test_render --gtest_brief=1
    step test_gaussians 60 test_gaussians --gtest_brief=1
    step test_tracking 60 test_tracking --gtest_brief=1
    step test_planes 60 test_planes --gtest_brief=1
    step test_common 30 test_common --gtest_brief=1
    step test_slam 120 test_slam --gtest_brief=1
    step bench_cuda 90 rrg_bench --benchmark_filter='cuda' --benchmark_min_time=0.2
    if command -v compute-sanitizer > /dev/null; then
      step sanitizer_tsdf 90 compute-sanitizer --error-exitcode=1 test_tsdf --gtest_brief=1 \
        --gtest_filter='TsdfStorage.*:TsdfRaycast.*:TsdfMesh*'
    fi
    ;;
  *)
    echo "usage: scripts/gpu_checks.sh bundle|device" >&2
    exit 2
    ;;
esac
