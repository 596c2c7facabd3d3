#!/usr/bin/env bash
# Configures and builds libvox. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
# A unity build (CMakeLists.txt) unless the caller says -DCMAKE_UNITY_BUILD=OFF: the first build in about 3/4 of the
# CPU time of one file at a time.
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON "$@" >/dev/null
ninja -C "$build" -j"$(nproc)"
