#!/usr/bin/env bash
# Solid fill benchmark (issue 11): vox-voxelize with and without --fill, whole process (read, voxelize, fill, write
# the grid file), on the 69k-triangle scanned Stanford bunny (open: decided by winding number) and the course's
# closed 40k bunny (flood fill), at several resolutions. The surface alone is the baseline of the same run: the table
# gives the seconds --fill adds, the ratio of the two wall times, and both peak memories (ru_maxrss).
# Usage: bench/fill.sh [BUILD_DIR] [RESOLUTIONS...]   (default 256 1024 2048; REPEAT runs each, fastest kept)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
resolutions=("${@:-256 1024 2048}")
read -r -a resolutions <<<"${resolutions[*]}"
seed=${VOX_SEED_DIR:-$root/data}
meshes=("${MESHES:-$seed/meshes/bun_zipper.ply $seed/6837/scenes/bunny_40k.obj}")
read -r -a meshes <<<"${meshes[*]}"
repeat=${REPEAT:-3}
threads=${THREADS:-$(nproc)}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

field() { grep "^$1: " "$2" | head -1 | cut -d' ' -f2; }
best() {  # best CMD... : runs REPEAT times, keeps the stats of the fastest total
  local bestTotal=""
  for _ in $(seq "$repeat"); do
    "$@" >"$tmp/out" 2>"$tmp/err" || { cat "$tmp/err" >&2; return 1; }
    local total
    total=$(field total_seconds "$tmp/err")
    if [ -z "$bestTotal" ] || awk "BEGIN{exit !($total < $bestTotal)}"; then
      bestTotal=$total
      cp "$tmp/err" "$tmp/best"
    fi
  done
}

echo "threads: $threads, best of $repeat"
printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n" mesh res "surface s" "fill s" "added s" ratio \
  "surface MB" "fill MB" "solid cells" "how it decided"
for mesh in "${meshes[@]}"; do
  for res in "${resolutions[@]}"; do
    best "$build/vox-voxelize" "$mesh" -o "$tmp/s.vgrid" --res "$res" --threads "$threads" --stats
    base=$(field total_seconds "$tmp/best") baseMem=$(field peak_memory_mb "$tmp/best")
    best "$build/vox-voxelize" "$mesh" -o "$tmp/f.vgrid" --res "$res" --threads "$threads" --stats --fill
    fill=$(field total_seconds "$tmp/best") fillMem=$(field peak_memory_mb "$tmp/best")
    how=$(grep -o 'fill: [^,]*' "$tmp/best" | head -1 | cut -d' ' -f2- | sed 's/|/\\|/g')
    printf "| %s | %s | %.2f | %.2f | %.2f | %.2f | %s | %s | %s | %s |\n" "$(basename "$mesh")" "$res" "$base" "$fill" \
      "$(awk "BEGIN{print $fill - $base}")" "$(awk "BEGIN{print $fill / $base}")" "$baseMem" "$fillMem" \
      "$(field solid_cells "$tmp/best")" "$how"
    rm -f "$tmp"/*.vgrid
  done
done
