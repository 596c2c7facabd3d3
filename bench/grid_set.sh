#!/usr/bin/env bash
# Grid sets at scale (issue 13): wall time and peak memory per process of the single grid against the set, on one
# process and over MPI ranks, and a batch of many small meshes. Prints a Markdown table row per run on stdout.
# Usage: bench/grid_set.sh BUILD_DIR WHAT...   with WHAT one of
#   single:RES            vox-voxelize MESH --res RES
#   set:RES:B             vox-voxelize MESH --res RES --bricks B B B
#   fill:RES              vox-voxelize MESH --res RES --fill
#   setfill:RES:B         vox-voxelize MESH --res RES --bricks B B B --fill
#   info:RES[:B]          vox-info --json --cells of the single grid (or of the set of B^3 bricks) at RES
#   mpi:RES:B:K           mpirun -n K vox-voxelize-mpi MESH --res RES --bricks B B B
#   batch:N:RES:K         N meshes (made from the seed meshes, transformed) through vox-voxelize-mpi --batch
# Environment: MESH (default the 69k bunny bun_zipper.ply), OUT (scratch folder, default /tmp/vox_bench_set; its
# outputs are removed after each run).
set -euo pipefail
BIN=$(cd "$1" && pwd)
shift
ROOT=$(cd "$(dirname "$0")/.." && pwd)
MESH=${MESH:-${VOX_SEED_DIR:-$ROOT/data}/meshes/bun_zipper.ply}
OUT=${OUT:-/tmp/vox_bench_set}
mkdir -p "$OUT"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# time -v of every process: the wall time of the command, the largest "Maximum resident set size" of its ranks.
measure() {  # measure LABEL COMMAND...
  local label=$1
  shift
  rm -rf "$OUT"/run* "$OUT"/batch_out
  local start end
  start=$(date +%s.%N)
  "$@" 2>"$OUT/stderr" >/dev/null || { echo "$label: failed"; cat "$OUT/stderr" >&2; return 1; }
  end=$(date +%s.%N)
  local peak files bytes
  peak=$(grep "Maximum resident" "$OUT/stderr" | awk '{print $6}' | sort -n | tail -1)
  files=$(find "$OUT" -maxdepth 2 -name '*.vgrid' -path "$OUT/run*" -o -maxdepth 2 -path "$OUT/batch_out/*" | wc -l)
  bytes=$( (du -scb "$OUT"/run* "$OUT"/batch_out 2>/dev/null || true) | tail -1 | cut -f1)
  awk -v l="$label" -v s="$start" -v e="$end" -v p="$peak" -v f="$files" -v b="$bytes" \
    'BEGIN { printf "| %s | %.2f | %.0f | %d | %.0f |\n", l, e - s, p / 1024, f, b / 1048576 }'
  grep -E "^(occupied_cells|references|voxelize_seconds|rank_)" "$OUT/stderr" | sed 's/^/    /' >&2 || true
}

make_batch() {  # make_batch N: N OBJ files, each a seed mesh under a random rotation and scale
  local n=$1
  [ -f "$OUT/batch_$n/list.txt" ] && return
  mkdir -p "$OUT/batch_$n"
  python3 - "$ROOT" "$OUT/batch_$n" "$n" "${VOX_SEED_DIR:-$ROOT/data}" <<'PY'
import math, random, sys, os
root, out, n, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
def load(path):
    vs, fs = [], []
    for line in open(path):
        p = line.split()
        if not p: continue
        if p[0] == 'v': vs.append(tuple(map(float, p[1:4])))
        elif p[0] == 'f': fs.append([int(x.split('/')[0]) for x in p[1:]])
    return vs, fs
meshes = [load(os.path.join(root, 'scenes', m)) for m in ('bunny_1k.obj', 'teapot.obj', 'cube.obj')]
meshes.append(load(os.path.join(seed, 'meshes', 'spot.obj')))
rng = random.Random(13)
with open(os.path.join(out, 'list.txt'), 'w') as lst:
    for i in range(n):
        vs, fs = meshes[i % len(meshes)]
        a, b = rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)
        s = [rng.uniform(0.5, 2) for _ in range(3)]
        def tf(v):
            x, y, z = v[0] * s[0], v[1] * s[1], v[2] * s[2]
            x, y = x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)
            y, z = y * math.cos(b) - z * math.sin(b), y * math.sin(b) + z * math.cos(b)
            return x, y, z
        path = os.path.join(out, 'm%04d.obj' % i)
        with open(path, 'w') as f:
            for v in vs: f.write('v %.17g %.17g %.17g\n' % tf(v))
            for face in fs: f.write('f ' + ' '.join(map(str, face)) + '\n')
        lst.write(path + '\n')
PY
}

T="/usr/bin/time -v"
echo "| run | wall s | peak MB per process (max) | grid files | output MB |"
echo "|---|---|---|---|---|"
for what in "$@"; do
  IFS=: read -r kind a b c <<<"$what"
  case $kind in
    single) measure "single $a^3" $T "$BIN/vox-voxelize" "$MESH" -o "$OUT/run.vgrid" --res "$a" --stats ;;
    set) measure "set $a^3, $b^3 bricks" $T "$BIN/vox-voxelize" "$MESH" -o "$OUT/run.vgrid" --res "$a" \
      --bricks "$b" "$b" "$b" --stats ;;
    fill) measure "single $a^3 --fill" $T "$BIN/vox-voxelize" "$MESH" -o "$OUT/run.vgrid" --res "$a" --fill --stats ;;
    setfill) measure "set $a^3, $b^3 bricks, --fill" $T "$BIN/vox-voxelize" "$MESH" -o "$OUT/run.vgrid" --res "$a" \
      --bricks "$b" "$b" "$b" --fill --stats ;;
    info) "$BIN/vox-voxelize" "$MESH" -o "$OUT/info.vgrid" --res "$a" ${b:+--bricks $b $b $b} -q
      measure "vox-info --json --cells, $a^3${b:+, $b^3 bricks}" $T "$BIN/vox-info" "$OUT/info.vgrid" --json --cells
      rm -rf "$OUT/info.vgrid" "$OUT/info.bricks" ;;
    mpi) measure "mpi K=$c, $a^3, $b^3 bricks" mpirun --oversubscribe -n "$c" $T "$BIN/vox-voxelize-mpi" "$MESH" \
      -o "$OUT/run.vgrid" --res "$a" --bricks "$b" "$b" "$b" --stats ;;
    batch) make_batch "$a"
      measure "batch K=$c, $a meshes at $b" mpirun --oversubscribe -n "$c" $T "$BIN/vox-voxelize-mpi" \
        --batch "$OUT/batch_$a/list.txt" -o "$OUT/batch_out" --res "$b" --stats ;;
    *) echo "unknown run $what" >&2; exit 1 ;;
  esac
done
