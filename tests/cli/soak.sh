#!/usr/bin/env bash
# Soak: random scenes through vox-voxelize, vox-trace and vox-export with their invariants checked
# (tests/soak/soak.py). VOX_SOAK_SCENES sets the count: 50 by default, 16 in a sanitizer build (CI time).
# Usage: soak.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
for tool in vox-voxelize vox-trace vox-export; do
  [ -x "$build/$tool" ] || { echo "missing $build/$tool"; exit 1; }
done
count=50
grep -q '^VOX_SANITIZE:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null && count=16
exec python3 "$src/tests/soak/soak.py" "$build" "${VOX_SOAK_SCENES:-$count}"
