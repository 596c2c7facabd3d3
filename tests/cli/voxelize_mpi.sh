#!/usr/bin/env bash
# vox-voxelize-mpi (issue 13) under mpirun: a grid set from K = 1..4 ranks (oversubscribed on small machines,
# including more ranks than bricks) equals the single-process grid cell for cell; a failing rank fails the run with
# its message and leaves no manifest; a batch with one corrupt scene finishes the others, names the bad one, exits 2.
# Usage: voxelize_mpi.sh BUILD_DIR SOURCE_DIR
set -u
BIN=$1
SRC=$2
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
M=$BIN/vox-voxelize-mpi
if ! command -v mpirun >/dev/null; then
  # CMake builds the tool only where MPI is found; without mpirun there is nothing to run it with.
  [ ! -e "$M" ] || { echo "FAIL vox-voxelize-mpi built but no mpirun"; exit 1; }
  echo "voxelize_mpi.sh: skipped, Open MPI not installed (scripts/install-deps.sh installs it)"
  exit 0
fi
[ -x "$M" ] || { echo "FAIL mpirun present but $M not built"; exit 1; }
# CI runs as root, which Open MPI refuses without these (DEBIAN-NOTES trap 7).
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Under the sanitizers every rank runs several times slower: fewer rank counts (still 1 and more than the bricks).
ALL_K="1 2 3 4"
SOME_K="3 4"
BATCH_K="1 3"
if grep -q "VOX_SANITIZE:BOOL=ON" "$BIN/CMakeCache.txt" 2>/dev/null; then
  # Open MPI 4.1 keeps allocations of its own past MPI_Finalize, which LeakSanitizer reports as leaks that are not
  # ours (not yet confirmed on this machine: the sanitizer build did not finish in the session that wrote this).
  export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0
  ALL_K="1 3"
  SOME_K="3"
  BATCH_K="2"
fi
CHECK_TIMEOUT=300
# shellcheck source=lib/check.sh
source "$(dirname "$0")/lib/check.sh"
same() {  # same NAME FILE1 FILE2
  if cmp -s "$2" "$3"; then passes=$((passes + 1)); else echo "FAIL $1: $2 and $3 differ"; fails=$((fails + 1)); fi
}
RUN="mpirun --oversubscribe -n"
V=$BIN/vox-voxelize
I=$BIN/vox-info
S=$SRC/scenes

check help 0 "$M" --help
grep -q -- "--batch" "$T/out" || { echo "FAIL help lacks --batch"; fails=$((fails + 1)); }

# Sets: spheres, ellipsoid, triangles, planes, user bounds; K = 1, 2, 3, 4 ranks.
set_case() {  # set_case TAG SCENE "ARGS" "BRICKS" "RANK COUNTS"
  local tag=$1 scene=$2 args=$3 bricks=$4 ranks=$5
  check "$tag single" 0 "$V" "$scene" -o "$T/$tag.vgrid" $args -q
  check "$tag info" 0 "$I" "$T/$tag.vgrid" --json --cells --primitives
  mv "$T/out" "$T/$tag.json"
  for K in $ranks; do
    check "$tag K=$K" 0 $RUN $K "$M" "$scene" -o "$T/${tag}_$K.vgrid" $args --bricks $bricks -q
    check "$tag K=$K info" 0 "$I" "$T/${tag}_$K.vgrid" --json --cells --primitives
    same "$tag: set from $K ranks equals the single grid" "$T/$tag.json" "$T/out"
  done
}
# (Each mpirun costs about a second of start-up: the rank counts are spread over the cases, all four on two.)
set_case bunny "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12" "3 2 2" "$ALL_K"
set_case squashed "$S/scene2_13_rotated_squashed_sphere.txt" "--grid 6 5 4" "6 5 4" "$ALL_K"  # one-cell bricks
set_case plane "$S/scene6_03_sphere_plane.txt" "--grid 9 8 7" "2 1 1" "$SOME_K"  # more ranks than bricks
set_case bounds "$S/scene5_05_sphere_triangles.txt" "--grid 12 10 8 --bounds -0.5 -0.6 -0.4 0.7 0.5 0.6" "5 3 2" "2"

# --fill with --bricks: rank 0 fills over the written bricks; the same solid cells as vox-voxelize --fill (vox-info
# counts solid cells and their runs, vox-export draws them), closed (flood) and open (winding number) meshes.
fill_case() {  # fill_case TAG SCENE "ARGS" "BRICKS" "RANK COUNTS"
  local tag=$1 scene=$2 args=$3 bricks=$4 ranks=$5
  check "$tag fill single" 0 "$V" "$scene" -o "$T/$tag.vgrid" $args --fill -q
  check "$tag fill info" 0 "$I" "$T/$tag.vgrid" --json --cells
  mv "$T/out" "$T/$tag.json"
  grep -q '"solid_cells": [1-9]' "$T/$tag.json" || { echo "FAIL $tag: nothing filled"; fails=$((fails + 1)); }
  check "$tag fill export" 0 "$BIN/vox-export" "$T/$tag.vgrid" -o "$T/$tag.ply" --faces all --color none -q
  for K in $ranks; do
    check "$tag fill K=$K" 0 $RUN $K "$M" "$scene" -o "$T/${tag}_$K.vgrid" $args --bricks $bricks --fill -q
    check "$tag fill K=$K info" 0 "$I" "$T/${tag}_$K.vgrid" --json --cells
    same "$tag: filled set from $K ranks equals the single grid" "$T/$tag.json" "$T/out"
    check "$tag fill K=$K export" 0 "$BIN/vox-export" "$T/${tag}_$K.vgrid" -o "$T/${tag}_$K.ply" --faces all --color none -q
    same "$tag: filled set from $K ranks exports as the single grid" "$T/$tag.ply" "$T/${tag}_$K.ply"
  done
}
fill_case fbunny "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12" "3 2 2" "$SOME_K"
fill_case fopen "${VOX_SEED_DIR:-$SRC/data}/meshes/bun_zipper.ply" "--res 20" "7 5 3" "2"

# A failing rank: bricks cannot be written (each about 300 KB, over a 64 KiB file-size limit; the scene file is
# small). The run fails with that message, exit 3, on every rank count; no manifest, and no file of the new set:
# rank 0 removes its generation folder once every rank has stopped. Over an old set, that set stays whole. The limit
# is set inside each rank (mpirun's own shared-memory files would exceed it; TCP between ranks instead), and the tool
# turns SIGXFSZ into EFBIG itself, so the write fails with a message.
LIMITED=(--mca btl self,tcp bash -c 'ulimit -f 64; exec "$@"' _)
for K in 1 3; do
  check "failing rank K=$K" 3 $RUN $K "${LIMITED[@]}" "$M" "$S/scene5_01_sphere.txt" -o "$T/stuck$K.vgrid" --grid 160 160 160 --bricks 2 2 2 -q
  grep -q "b_._._.\.vgrid" "$T/err" || { echo "FAIL failing rank K=$K: message lacks the brick"; cat "$T/err"; fails=$((fails + 1)); }
  [ "$(grep -c error "$T/err")" = 1 ] || { echo "FAIL failing rank K=$K: not one error line"; cat "$T/err"; fails=$((fails + 1)); }
  [ ! -e "$T/stuck$K.vgrid" ] || { echo "FAIL failing rank K=$K left a manifest"; fails=$((fails + 1)); }
  [ -z "$(find "$T/stuck$K.bricks" -type f 2>/dev/null)" ] || { echo "FAIL failing rank K=$K left files"; fails=$((fails + 1)); }
done
files_of() { (cd "$T" && find "$1.vgrid" "$1.bricks" -type f 2>/dev/null | sort); }
check "old set" 0 $RUN 2 "$M" "$S/bunny_1k.obj" -o "$T/rr.vgrid" --res 20 --bricks 3 3 3 -q
check "old set info" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
mv "$T/out" "$T/rr.json"
files_of rr >"$T/rr.files"
check "rerun with a failing rank" 3 $RUN 3 "${LIMITED[@]}" "$M" "$S/scene5_01_sphere.txt" -o "$T/rr.vgrid" --grid 160 160 160 --bricks 2 2 2 -q
same "old set's files after a failing rank" "$T/rr.files" <(files_of rr)
check "old set after a failing rank" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
same "old set reads as before after a failing rank" "$T/rr.json" "$T/out"
# A rank killed (SIGTERM) once bricks are written: its handler removes the new set's folder, mpirun ends the job, no
# manifest is written (rank 0 waits for every rank's outcome first); the old set stays whole.
$RUN 2 "$M" "${VOX_SEED_DIR:-$SRC/data}/meshes/bun_zipper.ply" -o "$T/rr.vgrid" --res 1600 \
  --bricks 8 8 8 -q 2>"$T/err" &
pid=$!
for _ in $(seq 600); do
  [ -n "$(find "$T/rr.bricks" -mindepth 2 -name 'b_*' 2>/dev/null | grep -v -F -f "$T/rr.files")" ] && break
  sleep 0.05
done
pkill -TERM -n -P $pid  # the newest rank
wait $pid
code=$?
[ $code != 0 ] || { echo "FAIL a run with a killed rank exited 0"; fails=$((fails + 1)); }
sleep 1  # ranks end after mpirun reports
same "old set's files after a killed rank" "$T/rr.files" <(files_of rr)
check "old set after a killed rank" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
same "old set reads as before after a killed rank" "$T/rr.json" "$T/out"
# Every error line is escaped like vox-voxelize's: a control byte of a scene's name never reaches the terminal raw.
esc=$(printf 'bad\033name.obj')
check "control bytes in a name" 2 $RUN 2 "$M" "$T/$esc" -o "$T/x.vgrid" --bricks 1 1 1 -q
grep -q -F 'bad\x1bname.obj' "$T/err" && ! grep -q "$(printf '\033')" "$T/err" ||
  { echo "FAIL control bytes printed raw"; cat -v "$T/err"; fails=$((fails + 1)); }
check "bad scene K=2" 2 $RUN 2 "$M" "$T/missing.obj" -o "$T/x.vgrid" --bricks 1 1 1 -q
[ "$(grep -c "missing.obj" "$T/err")" = 1 ] || { echo "FAIL bad scene: one line naming it"; cat "$T/err"; fails=$((fails + 1)); }
check "no mode" 1 $RUN 1 "$M" -o "$T/x.vgrid"
[ ! -e "$T/x.vgrid" ] || { echo "FAIL a failed run left a manifest"; fails=$((fails + 1)); }

# Batch: good scenes, one corrupt scene; the others finish and equal single runs byte for byte; exit 2.
mkdir -p "$T/in"
cp "$S/scene5_01_sphere.txt" "$S/scene5_02_spheres.txt" "$S/scene6_03_sphere_plane.txt" "$T/in/"
cp "$S/bunny_1k.obj" "$T/in/bunny.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n' >"$T/in/corrupt.obj"
{ echo "# a comment"; for f in scene5_01_sphere.txt scene5_02_spheres.txt corrupt.obj scene6_03_sphere_plane.txt bunny.obj; do echo "$T/in/$f"; done; } >"$T/list.txt"
for K in $BATCH_K; do
  rm -rf "$T/out$K"
  check "batch K=$K" 2 $RUN $K "$M" --batch "$T/list.txt" -o "$T/out$K" --res 16 -q
  grep -q "corrupt.obj" "$T/err" || { echo "FAIL batch K=$K: bad scene not named"; cat "$T/err"; fails=$((fails + 1)); }
  [ "$(grep -c "error" "$T/err")" = 1 ] || { echo "FAIL batch K=$K: one error line expected"; cat "$T/err"; fails=$((fails + 1)); }
  [ ! -e "$T/out$K/corrupt.vgrid" ] || { echo "FAIL batch K=$K: grid of the bad scene"; fails=$((fails + 1)); }
  for name in scene5_01_sphere scene5_02_spheres scene6_03_sphere_plane bunny; do
    src=$(grep "/$name\." "$T/list.txt")
    [ -e "$T/single_$name.vgrid" ] || "$V" "$src" -o "$T/single_$name.vgrid" --res 16 -q
    same "batch K=$K: $name equals its single run" "$T/single_$name.vgrid" "$T/out$K/$name.vgrid"
  done
done
grep -v corrupt "$T/list.txt" >"$T/good.txt"
check "batch all good" 0 $RUN 2 "$M" --batch "$T/good.txt" -o "$T/outgood" --res 16 -q
check "batch with bricks" 1 $RUN 1 "$M" --batch "$T/good.txt" -o "$T/outb" --bricks 2 2 2 -q
echo "$T/in/bunny.obj" >>"$T/good.txt"
check "batch duplicate names" 1 $RUN 2 "$M" --batch "$T/good.txt" -o "$T/outdup" -q
grep -q "bunny.vgrid" "$T/err" || { echo "FAIL duplicate names not named"; cat "$T/err"; fails=$((fails + 1)); }

echo "voxelize_mpi.sh: $passes passed, $fails failed"
[ $fails = 0 ]
