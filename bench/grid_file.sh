#!/usr/bin/env bash
# Grid file versions (issue 26): a previous build's vox-voxelize (PREVIOUS=folder of its tools, writing version 2)
# and this build's (version 3) alternate on the same mesh and resolution, REPEAT times each; the median of each
# column is printed: whole-process seconds, write and sync seconds (--stats), the file's size, and the seconds
# this build's vox-info takes to read each file (both versions read by the same reader).
# Usage: PREVIOUS=/path/to/old/tools bench/grid_file.sh BUILD_DIR [RESOLUTIONS...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:?usage: PREVIOUS=DIR bench/grid_file.sh BUILD_DIR [RESOLUTIONS...]}
shift
previous=${PREVIOUS:?set PREVIOUS to the folder of the previous build tools}
resolutions=("${@:-1024 2048}")
mesh=${MESH:-${VOX_SEED_DIR:-$root/data}/meshes/derived/stanford_bunny_69k.obj}
repeat=${REPEAT:-5}
tmp=$(mktemp -d "${TMPDIR:-/var/tmp}/gridfile.XXXXXX")  # a disk, not tmpfs: sync must cost what it costs
trap 'rm -rf "$tmp"' EXIT

field() { grep "^$1: " "$2" | head -1 | cut -d' ' -f2; }
median() { sort -g | awk '{v[NR]=$1} END{print (NR%2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2)}'; }
readSeconds() {  # seconds for this build's vox-info to read FILE
  local start end
  start=$(date +%s.%N)
  "$build/vox-info" "$1" >/dev/null
  end=$(date +%s.%N)
  awk "BEGIN{printf \"%.4f\", $end - $start}"
}

echo "mesh: $(basename "$mesh"), median of $repeat alternating runs"
printf "%-6s %-9s %9s %9s %9s %10s %9s\n" res build total_s write_s sync_s file_MB read_s
for res in "${resolutions[@]}"; do
  for tag in previous this; do : >"$tmp/$tag.rows"; done
  for _ in $(seq "$repeat"); do
    for tag in previous this; do
      tools=$build
      [ "$tag" = previous ] && tools=$previous
      "$tools/vox-voxelize" "$mesh" -o "$tmp/$tag.vgrid" --res "$res" --stats --quiet 2>"$tmp/stats"
      echo "$(field total_seconds "$tmp/stats") $(field write_seconds "$tmp/stats") $(field sync_seconds "$tmp/stats")" \
        "$(stat -c %s "$tmp/$tag.vgrid") $(readSeconds "$tmp/$tag.vgrid")" >>"$tmp/$tag.rows"
    done
  done
  for tag in previous this; do
    cols=()
    for c in 1 2 3 4 5; do cols+=("$(cut -d' ' -f$c "$tmp/$tag.rows" | median)"); done
    printf "%-6s %-9s %9.3f %9.3f %9.3f %10.1f %9.3f\n" "$res" "$tag" "${cols[0]}" "${cols[1]}" "${cols[2]}" \
      "$(awk "BEGIN{print ${cols[3]} / 1e6}")" "${cols[4]}"
  done
done
