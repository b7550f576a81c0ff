#!/usr/bin/env bash
# Optional benchmark dependencies (not needed to build or test): Open3D 0.16 for the TSDF
# comparison (t::geometry::VoxelBlockGrid), Debian 12 package. Then configure with
# -DRRG_BENCH_OPEN3D=ON to build rrg_bench_open3d (bench/open3d, docs/tsdf.md).
set -euo pipefail
apt-get install -y libopen3d-dev
