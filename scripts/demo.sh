#!/usr/bin/env bash
# Installs, builds, voxelizes a bundled scene exactly and prints its statistics.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh"
"$root/scripts/build.sh" "$root/build" -DVOX_TESTS=OFF
mkdir -p "$root/out"
"$root/build/vox-voxelize" "$root/scenes/scene5_07_bunny_mesh_1k.txt" -o "$root/out/bunny.vgrid" --grid 15 15 12 --stats
"$root/build/vox-info" "$root/out/bunny.vgrid"
