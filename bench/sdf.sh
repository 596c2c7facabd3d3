#!/usr/bin/env bash
# Narrow-band signed distances (issue 38): `vox-voxelize --sdf 3` against OpenVDB 10's meshToLevelSet with the same
# half-width, voxel size and voxel centres (bench/openvdb_sdf.cpp), whole process each, runs alternating, the
# fastest of REPEAT kept. Also OpenVDB's sign errors on the cells both fields hold, and how far its magnitudes are
# from ours (exact: tests/distance_test.cpp); on closed meshes CGAL's exact inside test judges each disagreement.
# Usage: bench/sdf.sh [BUILD_DIR] [RESOLUTIONS...]   (default 256 1024; BUILD_DIR configured with -DVOX_BENCH=ON)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
resolutions=("${@:-256 1024}")
read -r -a resolutions <<<"${resolutions[*]}"
seed=${VOX_SEED_DIR:-$root/data}
meshes=("${MESHES:-$seed/meshes/bun_zipper.ply $seed/6837/scenes/bunny_40k.obj}")
read -r -a meshes <<<"${meshes[*]}"
repeat=${REPEAT:-3}
threads=${THREADS:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

field() { grep "^$1: " "$2" | head -1 | cut -d' ' -f2-; }
min() { if [ -z "$1" ]; then echo "$2"; else awk -v a="$1" -v b="$2" 'BEGIN{print (b < a) ? b : a}'; fi; }

echo "threads: $threads, fastest of $repeat, runs alternating"
printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n" mesh res "libvox s" "OpenVDB s" "OpenVDB / libvox" \
  "libvox MB" "OpenVDB MB" "OpenVDB sign errors / cells compared" "OpenVDB magnitude error (voxels)" \
  "CGAL on the disagreements"
for mesh in "${meshes[@]}"; do
  for res in "${resolutions[@]}"; do
    ours="" theirs="" oursMem="" theirsMem=""
    for _ in $(seq "$repeat"); do
      "$build/vox-voxelize" "$mesh" -o "$tmp/s.vgrid" --res "$res" --sdf 3 --threads "$threads" --stats -q 2>"$tmp/ours"
      ours=$(min "$ours" "$(field total_seconds "$tmp/ours")") oursMem=$(field peak_memory_mb "$tmp/ours")
      "$build/bench/openvdb_sdf" "$mesh" "$res" 3 "$threads" >"$tmp/theirs"
      theirs=$(min "$theirs" "$(field total_seconds "$tmp/theirs")") theirsMem=$(field peak_memory_mb "$tmp/theirs")
    done
    "$build/bench/openvdb_sdf" "$mesh" "$res" 3 "$threads" "$tmp/s.vgrid" >"$tmp/compare"
    printf "| %s | %s | %.2f | %.2f | %.2f | %s | %s | %s / %s | %s | %s |\n" "$(basename "$mesh")" "$res" "$ours" \
      "$theirs" "$(awk "BEGIN{print $theirs / $ours}")" "$oursMem" "$theirsMem" \
      "$(field openvdb_sign_errors "$tmp/compare")" "$(field compared_cells "$tmp/compare")" \
      "$(field magnitude_difference_voxels "$tmp/compare")" "$(field cgal_on_the_disagreements "$tmp/compare")"
    rm -f "$tmp"/*.vgrid
  done
done
