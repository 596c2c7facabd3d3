#!/usr/bin/env bash
# Voxelizer benchmark: the 69k-triangle Stanford bunny at several resolutions with every method, whole process
# (read, voxelize, write the grid file) and voxelization alone, cells tested, occupied cells, references, peak
# memory; OpenVDB's meshToUnsignedDistanceField (band of one voxel) in the same run as the baseline.
# Usage: bench/voxelize.sh [BUILD_DIR] [RESOLUTIONS...]   (build with -DVOX_BENCH=ON first)
# Each configuration runs REPEAT times (default 3); the fastest run is reported.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
resolutions=("${@:-256 1024 2048}")
read -r -a resolutions <<<"${resolutions[*]}"
mesh=${MESH:-${VOX_SEED_DIR:-$root/data}/meshes/bun_zipper.ply}
repeat=${REPEAT:-3}
threads=${THREADS:-$(nproc)}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

field() { grep "^$1: " "$2" | head -1 | cut -d' ' -f2; }
best() {  # best CMD... : runs REPEAT times, keeps the stats of the fastest total
  local bestTotal=""
  for _ in $(seq "$repeat"); do
    "$@" >"$tmp/out" 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }
    cat "$tmp/out" "$tmp/err" >"$tmp/all"
    local total
    total=$(field total_seconds "$tmp/all")
    if [ -z "$bestTotal" ] || awk "BEGIN{exit !($total < $bestTotal)}"; then
      bestTotal=$total
      cp "$tmp/all" "$tmp/best"
    fi
  done
}

echo "mesh: $(basename "$mesh"), threads: $threads, best of $repeat"
printf "%-6s %-8s %10s %10s %12s %12s %12s %10s %10s\n" res method wall_s vox_s cells_tested occupied references peak_MB vs_openvdb
for res in "${resolutions[@]}"; do
  best "$build/bench/openvdb_voxelize" "$mesh" "$res" "$threads"
  vdbTotal=$(field total_seconds "$tmp/best")
  printf "%-6s %-8s %10s %10s %12s %12s %12s %10s %10s\n" "$res" openvdb "$vdbTotal" "$(field voxelize_seconds "$tmp/best")" - \
    "$(field marked_voxels "$tmp/best")" - "$(field peak_memory_mb "$tmp/best")" 1.00
  for method in exact sat bbox center; do
    best "$build/vox-voxelize" "$mesh" -o "$tmp/g.vgrid" --res "$res" --method "$method" --threads "$threads" --stats --quiet
    total=$(field total_seconds "$tmp/best")
    printf "%-6s %-8s %10s %10s %12s %12s %12s %10s %10s\n" "$res" "$method" "$total" "$(field voxelize_seconds "$tmp/best")" \
      "$(field cells_tested "$tmp/best")" "$(field occupied_cells "$tmp/best")" "$(field references "$tmp/best")" \
      "$(field peak_memory_mb "$tmp/best")" "$(awk "BEGIN{printf \"%.2f\", $vdbTotal / $total}")"
  done
done
