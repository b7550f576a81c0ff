#!/usr/bin/env bash
# Builds the frame-decoding libFuzzer target with clang (-fsanitize=fuzzer,address,undefined) and
# runs it: RVL, RVL+zstd, PNG, JPEG, raw RGB8 / uint16 / float32 decoding (tests/fuzz/frame_fuzz.h).
# Not part of CI (minutes); the GCC test build runs the same target over 20k mutations (test_fuzz).
#   tests/fuzz/build_and_run.sh [RUNS]       RUNS defaults to 1000000
# Env: CXX_FUZZ (default clang++-14, else clang++), FUZZ_DIR (default build-fuzz), FUZZ_ARGS (extra
# libFuzzer flags). Needs clang and libclang-rt-<ver>-dev (Debian), plus the project's -dev packages.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
RUNS="${1:-1000000}"
OUT="${FUZZ_DIR:-$ROOT/build-fuzz}"
CXX="${CXX_FUZZ:-$(command -v clang++-14 || command -v clang++ || true)}"
if [ -z "$CXX" ]; then echo "[fuzz] no clang++ found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 2; fi
mkdir -p "$OUT/corpus" "$OUT/seeds" "$OUT/artifacts"

SRCS=("$ROOT/core/io/rvl.cpp" "$ROOT/core/io/frame_codec.cpp" "$ROOT/core/io/image_header.cpp"
      "$ROOT/tests/fuzz/frame_fuzz.cpp")
FLAGS=(-std=c++20 -O1 -g -fno-omit-frame-pointer -I"$ROOT" -isystem /usr/include/eigen3 -isystem /usr/include/opencv4)
LIBS=(-lopencv_imgcodecs -lopencv_imgproc -lopencv_core -lzstd)
SAN=(-fsanitize=address,undefined -fno-sanitize-recover=undefined)

echo "[fuzz] $CXX: building $OUT/frame_fuzzer"
"$CXX" "${FLAGS[@]}" "${SAN[@]}" -fsanitize=fuzzer "${SRCS[@]}" "$ROOT/tests/fuzz/frame_fuzz_target.cpp" \
  "${LIBS[@]}" -o "$OUT/frame_fuzzer"

# The seed corpus: valid encodings of every mode, written by a small program over the same code.
cat > "$OUT/write_seeds.cpp" <<'CPP'
#include "tests/fuzz/frame_fuzz.h"
#include <cstdio>
#include <string>
int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const auto seeds = rrg::fuzz::frame_fuzz_seeds();
  for (size_t i = 0; i < seeds.size(); ++i) {
    const std::string path = std::string(argv[1]) + "/seed-" + std::to_string(i);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f || std::fwrite(seeds[i].data(), 1, seeds[i].size(), f) != seeds[i].size()) return 1;
    std::fclose(f);
  }
  std::printf("[fuzz] %zu seeds\n", seeds.size());
  return 0;
}
CPP
"$CXX" "${FLAGS[@]}" "${SAN[@]}" "${SRCS[@]}" "$OUT/write_seeds.cpp" "${LIBS[@]}" -o "$OUT/write_seeds"
"$OUT/write_seeds" "$OUT/seeds"

echo "[fuzz] running $RUNS executions"
set +e
# OpenCV's libjpeg prints "Corrupt JPEG data" warnings for many mutated inputs: filtered out.
"$OUT/frame_fuzzer" -runs="$RUNS" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$OUT/artifacts/" ${FUZZ_ARGS:-} "$OUT/corpus" "$OUT/seeds" 2>&1 \
  | grep -v -E '^(Corrupt JPEG data|Premature end of JPEG|Invalid SOS|Bogus|Unsupported marker|Warning: |libpng (error|warning))' \
  | tee "$OUT/fuzz.log" | grep -v -E '^#[0-9]+\s+(NEW|REDUCE|pulse)'
rc=${PIPESTATUS[0]}
set -e
execs=$(grep -E 'stat::number_of_executed_units' "$OUT/fuzz.log" | awk '{print $2}')
echo "[fuzz] executions: ${execs:-unknown}, exit code $rc, artifacts: $(ls "$OUT/artifacts" | wc -l)"
exit "$rc"
