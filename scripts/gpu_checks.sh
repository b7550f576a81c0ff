#!/usr/bin/env bash
# The CUDA checks of a lent GPU session (../shared/GPU.md), prepared so that one device call does
# them all within its few minutes.
#
#   scripts/gpu_checks.sh bundle [BEFORE]
#                                  here: pack the CUDA test binaries, rrg_bench and rrg of build/
#                                  (built with -DCMAKE_CUDA_ARCHITECTURES=90 -DRRG_BUILD_BENCH=ON)
#                                  into .gpu/. BEFORE (optional): an rrg executable built from an
#                                  earlier commit; it is bundled as rrg_before, and the device runs
#                                  the 1280x720 scene with it too, side by side. GPU_CHECKS_BENCH=0
#                                  leaves rrg_bench out (the working tree that travels is <= 64 MiB).
#   scripts/gpu_checks.sh device   there, in one `run` call with carry=[".gpu"]:
#                                    run(command="scripts/gpu_checks.sh device", carry=[".gpu"], timeout_s=480)
#
# On the device, in order of importance, each step under its own time limit and all of them under
# one deadline (GPU_CHECKS_DEADLINE seconds, default 420) so a slow step cannot starve the rest:
#   1. the CUDA parity tests (TSDF, renderer, Gaussians, tracking, device layer);
#   2. the whole pipeline on the CUDA back end (`rrg synth` then `rrg run --device cuda`):
#      mirror_room 1280x720 (150 noisy frames; also with rrg_before when bundled), mirror_room
#      640x480 with reflections on and off, living_room 320x240, mirror_room 320x240 on and off
#      with the CPU runs' 1 cm voxels (300 noisy frames each);
#   3. the CUDA micro-benchmarks;
#   4. compute-sanitizer on the TSDF tests.
# A one-line verdict per step goes to $OUT/summary.txt (and stdout); every log, metrics.json and
# timings.json goes into $OUT/results.tar.gz (the device tool returns at most 8 files), rewritten
# after each step so a cut-off run still returns what it did.
set -uo pipefail
cd "$(dirname "$0")/.."

tests=(test_tsdf test_render test_gaussians test_tracking test_common)
tools=(rrg_bench rrg)

case "${1:-}" in
  bundle)
    [[ ${GPU_CHECKS_BENCH:-1} == 0 ]] && tools=(rrg)
    exes=()
    for t in "${tests[@]}" "${tools[@]}"; do
      [[ -x build/bin/$t ]] || { echo "gpu_checks: build/bin/$t is missing (build with tests and benchmarks first)" >&2; exit 2; }
      exes+=("build/bin/$t")
    done
    if [[ -n ${2:-} ]]; then
      [[ -x $2 && -f $2 ]] || { echo "gpu_checks: $2 is not an executable file" >&2; exit 2; }
      before=$(mktemp -d)
      trap 'rm -rf "$before"' EXIT
      cp "$2" "$before/rrg_before"
      exes+=("$before/rrg_before")
    fi
    ../shared/tools/gpu-bundle -o .gpu "${exes[@]}"
    ls -l .gpu/bundle.tar.xz
    ;;
  device)
    : "${OUT:?gpu_checks: device mode writes under \$OUT (the device tool sets it)}"
    [[ -f .gpu/bundle.tar.xz ]] || { echo "gpu_checks: .gpu/bundle.tar.xz not carried" >&2; exit 2; }
    g=/tmp/g logs=/tmp/gpu_logs data=/tmp/gpu_data
    mkdir -p "$g" "$logs" "$data" && tar -C "$g" -xJf .gpu/bundle.tar.xz || exit 2
    export LD_LIBRARY_PATH=$g/lib PATH=$g/bin:$PATH
    # the CLI tests run the bundled rrg on the repo's test data (not the build tree's compiled-in paths)
    export RRG_CLI=$g/bin/rrg RRG_TEST_DATA_DIR=$PWD/tests/data
    deadline=$((SECONDS + ${GPU_CHECKS_DEADLINE:-420}))
    { nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader; nproc; } | tee "$logs/device.txt"
    pack() { tar -C "$logs" -czf "$OUT/results.tar.gz.part" . && mv "$OUT/results.tar.gz.part" "$OUT/results.tar.gz"; }
    step() {  # step NAME SECONDS COMMAND...
      local name=$1 limit=$2
      shift 2
      local left=$((deadline - SECONDS))
      if ((left < 10)); then
        echo "$name: SKIPPED (deadline)" | tee -a "$OUT/summary.txt"
        return 1
      fi
      ((limit > left)) && limit=$left
      local t0=$SECONDS
      timeout "$limit" "$@" > "$logs/$name.txt" 2>&1
      local rc=$?
      local verdict="ok"
      ((rc == 124)) && verdict="TIMED OUT after ${limit}s"
      ((rc != 0 && rc != 124)) && verdict="FAILED (rc $rc)"
      echo "$name: $verdict, $((SECONDS - t0)) s" | tee -a "$OUT/summary.txt"
      grep -E "^\[  FAILED  \]|PASSED|error|Error" "$logs/$name.txt" | head -20 | tee -a "$OUT/summary.txt"
      pack
      return $rc
    }
    run_scene() {  # run_scene [--with EXE] [--limit SECONDS] NAME DATASET EXTRA_ARGS...
      local exe=rrg limit=150
      [[ $1 == --with ]] && { exe=$2; shift 2; }
      [[ $1 == --limit ]] && { limit=$2; shift 2; }
      local name=$1 dataset=$2
      shift 2
      step "$name" "$limit" "$exe" run --dataset "$dataset" --out "$data/$name" --device cuda --no-progress "$@"
      for f in metrics.json timings.json; do
        [[ -f $data/$name/$f ]] && cp "$data/$name/$f" "$logs/$name.$f"
      done
      pack
    }

    # 1. parity
    step test_tsdf 60 test_tsdf --gtest_brief=1
    step test_render 45 test_render --gtest_brief=1
    step test_gaussians 30 test_gaussians --gtest_brief=1
    step test_tracking 45 test_tracking --gtest_brief=1
    step test_common 20 test_common --gtest_brief=1
    # 2. the whole pipeline
    step synth_mr720 60 rrg synth --preset mirror_room --frames 150 --width 1280 --height 720 \
      --novel 10 --noise --out "$data/mr720"
    run_scene run_mr720 "$data/mr720"
    if [[ -x $g/bin/rrg_before ]]; then  # the same frames with the earlier build, side by side
      run_scene --with rrg_before run_mr720_before "$data/mr720"
    fi
    step synth_mr640 40 rrg synth --preset mirror_room --frames 300 --width 640 --height 480 --noise \
      --out "$data/mr640"
    run_scene --limit 240 run_mr640 "$data/mr640" --ablate-reflections
    step synth_lr320 30 rrg synth --preset living_room --frames 300 --noise --out "$data/lr320"
    run_scene run_lr320 "$data/lr320"
    # 3. micro-benchmarks (the host's share too: densification, ORB extraction)
    [[ -x $g/bin/rrg_bench ]] && step bench 60 rrg_bench --benchmark_min_time=0.2 \
      --benchmark_filter='densify|orb_extract|cuda.*(tsdf_(fuse|raycast)_(640x480|1280x720)/5mm|mapping_step|tracking|vertex)|(tsdf_(fuse|raycast)_(640x480|1280x720)/5mm|mapping_step|tracking|vertex|render).*cuda'
    step synth_mr320 30 rrg synth --preset mirror_room --frames 300 --noise --out "$data/mr320"
    # the CPU runs' voxels (1 cm, truncation 4 cm), for figures comparable with them
    run_scene run_mr320_1cm "$data/mr320" --ablate-reflections --set tsdf.voxel_size=0.01 --set tsdf.truncation=0.04
    # office has no reflective surface: reflections on vs off must agree (#8: within 0.3 dB)
    step synth_of320 30 rrg synth --preset office --frames 300 --noise --out "$data/of320"
    run_scene run_of320 "$data/of320" --ablate-reflections
    # 4. memory errors
    if command -v compute-sanitizer > /dev/null; then
      step sanitizer_tsdf 60 compute-sanitizer --error-exitcode=1 test_tsdf --gtest_brief=1 \
        --gtest_filter='TsdfStorage.*:TsdfRaycast.*:TsdfMesh*:RaycastWarp.*'
    fi
    pack
    ;;
  *)
    echo "usage: scripts/gpu_checks.sh bundle [BEFORE] | device" >&2
    exit 2
    ;;
esac
