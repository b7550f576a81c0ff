#!/usr/bin/env bash
# ctest entry of the browser viewer's end-to-end test (docs/viewer.md): builds web_viewer/
# (npm ci when its lock file changed, npm run build) and runs viewer_e2e.mjs in headless Chromium.
# Usage: tests/web/run.sh RRG_BINARY ARTIFACT_DIR. RRG_SKIP_WEB_TESTS=1 skips (exit 77).
set -euo pipefail
rrg=$1
artifacts=$2
here=$(cd "$(dirname "$0")" && pwd)
viewer="$here/../../web_viewer"
if [ "${RRG_SKIP_WEB_TESTS:-0}" = 1 ]; then echo "[web] skipped (RRG_SKIP_WEB_TESTS=1)"; exit 77; fi
for tool in node npm; do
  if ! command -v "$tool" > /dev/null; then
    echo "[web] '$tool' is missing: the viewer test needs Node.js >= 18 and npm (Debian: apt-get install nodejs npm)," \
         "or set RRG_SKIP_WEB_TESTS=1 to skip it" >&2
    exit 1
  fi
done
chromium=${RRG_CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then
  echo "[web] $chromium is missing: install Debian's chromium (scripts/install_deps.sh does), or set RRG_SKIP_WEB_TESTS=1" >&2
  exit 1
fi
cd "$viewer"
stamp=node_modules/.rrg-lock-stamp
if [ ! -f "$stamp" ] || ! cmp -s package-lock.json "$stamp"; then
  npm ci --no-audit --no-fund
  cp package-lock.json "$stamp"
fi
npm run build
exec node "$here/viewer_e2e.mjs" "$rrg" "$artifacts"
