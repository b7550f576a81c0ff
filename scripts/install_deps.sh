#!/usr/bin/env bash
# Installs the Debian packages the build and tests need. Idempotent: packages already present are
# skipped, so a second run costs one dpkg query. Exact package names, Debian 12 (bookworm).
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev          # small math
  libspdlog-dev          # logging
  libcli11-dev           # command line
  nlohmann-json3-dev     # JSON output
  libgtest-dev libgmock-dev  # tests
  libbenchmark-dev       # bench/
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-features2d-dev  # image I/O, ORB
  zlib1g-dev libzstd-dev     # SPZ (gzip), RVL+zstd depth
  libdraco-dev               # Draco meshes
  libyaml-cpp-dev            # session config files
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc  # the service, remote semantic cue
  libcpp-httplib-dev         # the service's Prometheus endpoint
  libssl-dev                 # the service's tokens (RAND_bytes, SHA-256)
  nginx                      # tests/deploy: the session-affine gRPC proxy in front of 3 servers
  chromium                   # the browser viewer's end-to-end test (tests/web, headless)
  curl                       # quickstart.sh prints the server's Prometheus metrics
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "[deps] installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "[deps] done"
