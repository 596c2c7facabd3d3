#!/usr/bin/env bash
# Installs, builds and runs every test. Usage: scripts/test.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh" --clients
build=${1:-$root/build}
shift || true
"$root/scripts/build.sh" "$build" -DVOX_TESTS=ON "$@"
cd "$build"
ctest --output-on-failure -j2 --timeout 900
