#!/usr/bin/env bash
# Optional benchmark dependencies (not needed to build or test): Open3D 0.16 for the TSDF
# comparison (t::geometry::VoxelBlockGrid), Debian 12 package.
set -euo pipefail
apt-get install -y libopen3d-dev
