#!/usr/bin/env bash
# Voxel-format export benchmark: whole vox-export process (read the grid, write the file) for .binvox, .vox and
# .vdb, with the exposed-faces binary PLY mesh of the same grid as the baseline in the same run (ratio = format
# time / PLY time), plus voxels, output size and peak memory. The grid is MESH voxelized with --fill.
# Usage: bench/export_formats.sh [BUILD_DIR] [RESOLUTIONS...]   (default 256 1024; no benchmark build needed)
# Each export runs REPEAT times (default 3); the fastest wall time is reported, with its peak memory.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
resolutions=("${@:-256 1024}")
read -r -a resolutions <<<"${resolutions[*]}"
mesh=${MESH:-${VOX_SEED_DIR:-$root/data}/meshes/bun_zipper.ply}
repeat=${REPEAT:-3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

best() {  # best OUT: exports to OUT REPEAT times, prints "wall_s peak_MB" of the fastest
  local bestWall="" bestMem=""
  for _ in $(seq "$repeat"); do
    /usr/bin/time -f "%e %M" -o "$tmp/time" "$build/vox-export" "$tmp/g.vgrid" -o "$1" --quiet --color count
    read -r wall kb <"$tmp/time"
    if [ -z "$bestWall" ] || awk "BEGIN{exit !($wall < $bestWall)}"; then bestWall=$wall bestMem=$((kb / 1024)); fi
  done
  echo "$bestWall $bestMem"
}

echo "mesh: $(basename "$mesh") --fill, best of $repeat, $(nproc) threads"
printf "%-6s %-8s %12s %12s %8s %8s %12s %8s\n" res format occupied solid wall_s peak_MB bytes vs_ply
for res in "${resolutions[@]}"; do
  "$build/vox-voxelize" "$mesh" -o "$tmp/g.vgrid" --res "$res" --fill --quiet
  info=$("$build/vox-info" "$tmp/g.vgrid" --json)
  occ=$(echo "$info" | sed -n 's/.*"occupied_cells": \([0-9]*\).*/\1/p')
  solid=$(echo "$info" | sed -n 's/.*"solid_cells": \([0-9]*\).*/\1/p')
  read -r plyWall plyMem < <(best "$tmp/o.ply")
  printf "%-6s %-8s %12s %12s %8s %8s %12s %8s\n" "$res" ply "$occ" "$solid" "$plyWall" "$plyMem" \
    "$(stat -c %s "$tmp/o.ply")" 1.00
  for ext in binvox vox vdb; do
    if ! best "$tmp/o.$ext" >"$tmp/r" 2>"$tmp/err"; then
      printf "%-6s %-8s %s\n" "$res" "$ext" "refused: $(head -c 150 "$tmp/err")"
      continue
    fi
    read -r wall mem <"$tmp/r"
    printf "%-6s %-8s %12s %12s %8s %8s %12s %8s\n" "$res" "$ext" "$occ" "$solid" "$wall" "$mem" \
      "$(stat -c %s "$tmp/o.$ext")" "$(awk "BEGIN{printf \"%.2f\", $wall / $plyWall}")"
  done
done
