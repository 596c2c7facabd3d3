#!/usr/bin/env bash
# Grid sets (vox-voxelize --bricks, issue 13) as a user runs them: vox-info, vox-trace and vox-export give the same
# output for the set as for the single grid; a bad set or a failed write gives one line, the right exit code and no
# manifest. Usage: grid_set.sh BUILD_DIR SOURCE_DIR
set -u
BIN=$1
SRC=$2
SEED=${VOX_SEED_DIR:-$SRC/data}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# shellcheck source=lib/check.sh
source "$(dirname "$0")/lib/check.sh"
same() {  # same NAME FILE1 FILE2
  if cmp -s "$2" "$3"; then passes=$((passes + 1)); else echo "FAIL $1: $2 and $3 differ"; fails=$((fails + 1)); fi
}

V=$BIN/vox-voxelize
I=$BIN/vox-info
TR=$BIN/vox-trace
E=$BIN/vox-export
# Sanitized builds run the same checks on fewer brick counts.
SANITIZED=0
grep -q "VOX_SANITIZE:BOOL=ON" "$BIN/CMakeCache.txt" 2>/dev/null && SANITIZED=1

check help 0 "$V" --help
grep -q -- "--bricks" "$T/out" || { echo "FAIL help lacks --bricks"; fails=$((fails + 1)); }

# Spheres, a squashed sphere (ellipsoid), triangles, planes (never in cells), user bounds cutting primitives off.
compare_set() {  # compare_set TAG SCENE "GRID ARGS" "BRICKS"
  local tag=$1 scene=$2 args=$3 bricks=$4
  check "$tag single" 0 "$V" "$scene" -o "$T/$tag.vgrid" $args -q
  check "$tag set" 0 "$V" "$scene" -o "$T/${tag}_set.vgrid" $args --bricks $bricks -q
  check "$tag info" 0 "$I" "$T/$tag.vgrid" --json --cells --primitives
  mv "$T/out" "$T/$tag.json"
  check "$tag set info" 0 "$I" "$T/${tag}_set.vgrid" --json --cells --primitives
  same "$tag: vox-info --json --cells of set and grid" "$T/$tag.json" "$T/out"
}
S=$SRC/scenes
compare_set spheres "$S/scene5_02_spheres.txt" "--grid 15 15 3" "7 5 3"
compare_set plane "$S/scene6_03_sphere_plane.txt" "--grid 9 8 7" "2 3 1"
compare_set squashed "$S/scene2_13_rotated_squashed_sphere.txt" "--grid 6 5 4" "6 5 4"  # bricks of one cell
compare_set bounds "$S/scene5_05_sphere_triangles.txt" "--grid 12 10 8 --bounds -0.5 -0.6 -0.4 0.7 0.5 0.6" "5 3 2"
compare_set sat "$S/scene5_11_rotated_triangles.txt" "--grid 11 9 7 --method sat" "3 4 2"
compare_set bbox "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12 --method bbox" "4 4 4"
if [ $SANITIZED = 0 ]; then
  for b in "1 1 1" "1 5 1" "7 5 3"; do
    compare_set "bunny_${b// /x}" "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12" "$b"
  done
fi
# Bricks are files of their own, named by the manifest, inside a generation folder NAME.bricks/gHEX/ beside it.
gen() { ls -d "$T/$1.bricks"/g* | head -1; }  # gen TAG: the one generation folder of set TAG
[ "$(ls "$(gen spheres_set)" | wc -l)" -ge 2 ] || { echo "FAIL brick files"; fails=$((fails + 1)); }

# Traced images and exported meshes of a set equal those of the single grid, byte for byte.
for mode in shade voxels count normals depth; do
  check "trace $mode" 0 "$TR" "$T/spheres.vgrid" -o "$T/a_$mode.png" --size 64 48 --mode $mode -q
  check "trace set $mode" 0 "$TR" "$T/spheres_set.vgrid" -o "$T/b_$mode.png" --size 64 48 --mode $mode -q
  same "trace $mode of set and grid" "$T/a_$mode.png" "$T/b_$mode.png"
done
check "trace plane" 0 "$TR" "$T/plane.vgrid" -o "$T/a_plane.png" --size 64 48 -q
check "trace plane set" 0 "$TR" "$T/plane_set.vgrid" -o "$T/b_plane.png" --size 64 48 -q
same "trace of a set with a plane" "$T/a_plane.png" "$T/b_plane.png"
for faces in all exposed merged; do
  check "export $faces" 0 "$E" "$T/bbox.vgrid" -o "$T/a_$faces.ply" --faces $faces -q
  check "export set $faces" 0 "$E" "$T/bbox_set.vgrid" -o "$T/b_$faces.ply" --faces $faces -q
  same "export $faces of set and grid" "$T/a_$faces.ply" "$T/b_$faces.ply"
done
# Voxel formats too; binvox and .vox are written from the set's layers of bricks, never assembled (vox-export). Not
# .vdb: OpenVDB writes a new random UUID into every file's header.
for ext in binvox vox; do
  check "export $ext" 0 "$E" "$T/bbox.vgrid" -o "$T/a.$ext" -q
  check "export set $ext" 0 "$E" "$T/bbox_set.vgrid" -o "$T/b.$ext" -q
  same "export .$ext of set and grid" "$T/a.$ext" "$T/b.$ext"
done
for color in material none; do  # .vox by count above; by material the layers keep their primitive lists
  check "export vox $color" 0 "$E" "$T/bbox.vgrid" -o "$T/a_$color.vox" --color $color -q
  check "export set vox $color" 0 "$E" "$T/bbox_set.vgrid" -o "$T/b_$color.vox" --color $color -q
  same "export .vox --color $color of set and grid" "$T/a_$color.vox" "$T/b_$color.vox"
done

# A scene of planes only: no occupied cell, no brick file; the set's scene file keeps the planes.
printf 'OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\nLights { numLights 1 DirectionalLight { direction 0 0 -1 color 1 1 1 } }\nBackground { color 0 0 0 ambientLight 0.2 0.2 0.2 }\nMaterials { numMaterials 1 Material { diffuseColor 1 0 0 } }\nGroup { numObjects 1 MaterialIndex 0 Plane { normal 0 1 0 offset -1 } }\n' >"$T/planes.txt"
check "planes only single" 0 "$V" "$T/planes.txt" -o "$T/p.vgrid" -q
check "planes only set" 0 "$V" "$T/planes.txt" -o "$T/p_set.vgrid" --bricks 1 1 1 -q
check "planes trace" 0 "$TR" "$T/p.vgrid" -o "$T/p1.png" --size 32 32 -q
check "planes set trace" 0 "$TR" "$T/p_set.vgrid" -o "$T/p2.png" --size 32 32 -q
same "planes-only set traces as its grid" "$T/p1.png" "$T/p2.png"

# --fill with --bricks: the same solid cells as the single grid (vox-info counts them and their runs in
# memory_bytes; vox-export draws them), closed (flood) and open (winding number) meshes, several brick counts.
compare_fill() {  # compare_fill TAG SCENE "GRID ARGS" "BRICKS"
  local tag=$1 scene=$2 args=$3 bricks=$4
  check "$tag fill single" 0 "$V" "$scene" -o "$T/$tag.vgrid" $args --fill -q
  check "$tag fill set" 0 "$V" "$scene" -o "$T/${tag}_set.vgrid" $args --fill --bricks $bricks -q
  check "$tag fill info" 0 "$I" "$T/$tag.vgrid" --json --cells
  mv "$T/out" "$T/$tag.json"
  check "$tag fill set info" 0 "$I" "$T/${tag}_set.vgrid" --json --cells
  same "$tag: vox-info of the filled set and grid" "$T/$tag.json" "$T/out"
  grep -q '"solid_cells": [1-9]' "$T/out" || { echo "FAIL $tag: nothing filled"; fails=$((fails + 1)); }
  check "$tag fill export" 0 "$E" "$T/$tag.vgrid" -o "$T/$tag.ply" --faces all --color none -q
  check "$tag fill set export" 0 "$E" "$T/${tag}_set.vgrid" -o "$T/${tag}_set.ply" --faces all --color none -q
  same "$tag: export of the filled set and grid" "$T/$tag.ply" "$T/${tag}_set.ply"
  check "$tag fill binvox" 0 "$E" "$T/$tag.vgrid" -o "$T/$tag.binvox" -q
  check "$tag fill set binvox" 0 "$E" "$T/${tag}_set.vgrid" -o "$T/${tag}_set.binvox" -q
  same "$tag: binvox of the filled set and grid" "$T/$tag.binvox" "$T/${tag}_set.binvox"
  check "$tag fill vox" 0 "$E" "$T/$tag.vgrid" -o "$T/$tag.vox" -q
  check "$tag fill set vox" 0 "$E" "$T/${tag}_set.vgrid" -o "$T/${tag}_set.vox" -q
  same "$tag: .vox of the filled set and grid" "$T/$tag.vox" "$T/${tag}_set.vox"
}
compare_fill fill_bunny "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12" "7 5 3"
compare_fill fill_bunny1 "$S/scene5_07_bunny_mesh_1k.txt" "--grid 15 15 12" "1 1 1"
compare_fill fill_sphere "$S/scene5_01_sphere.txt" "--grid 7 6 5" "7 6 5"  # bricks of one cell
compare_fill fill_open "$SEED/meshes/bun_zipper.ply" "--res 24" "3 2 2"  # open: winding number
check "set fill says how" 0 "$V" "$S/scene5_07_bunny_mesh_1k.txt" -o "$T/say.vgrid" --grid 8 8 8 --fill --bricks 2 2 2
grep -q "fill: closed surface" "$T/err" || { echo "FAIL set --fill does not say how it decided"; fails=$((fails + 1)); }

# Usage errors: one line, exit 1, nothing written.
check "more bricks than cells" 1 "$V" "$S/scene5_01_sphere.txt" -o "$T/f.vgrid" --grid 4 4 4 --bricks 5 1 1
expect_err "more bricks than cells" "5 bricks on axis x"
check "zero bricks" 1 "$V" "$S/scene5_01_sphere.txt" -o "$T/f.vgrid" --bricks 0 1 1
[ ! -e "$T/f.vgrid" ] || { echo "FAIL usage error left a manifest"; fails=$((fails + 1)); }

# A brick folder that cannot be made: exit 3, no manifest.
touch "$T/blocked.bricks"
check "brick folder blocked" 3 "$V" "$S/scene5_01_sphere.txt" -o "$T/blocked.vgrid" --grid 8 8 8 --bricks 2 2 2
expect_err "brick folder blocked" "blocked.bricks"
[ ! -e "$T/blocked.vgrid" ] || { echo "FAIL failed set left a manifest"; fails=$((fails + 1)); }
check "set to a device" 3 "$V" "$S/scene5_01_sphere.txt" -o /dev/null --grid 8 8 8 --bricks 2 2 2
expect_err "set to a device" "regular file"
# A brick that cannot be written (larger than the file-size limit; the scene file is not): exit 3 with the message
# (not a death by SIGXFSZ), no manifest, and the new set's folder gone with it.
late_failure() {  # late_failure OUT: a 160^3 sphere in 2x2x2 bricks of about 300 KB each, under a 64 KiB limit
  (ulimit -f 64; exec "$V" "$S/scene5_01_sphere.txt" -o "$1" --grid 160 160 160 --bricks 2 2 2 -q)
}
check "brick write fails" 3 late_failure "$T/stuck.vgrid"
expect_err "brick write fails" "b_._._.\.vgrid: cannot write: File too large"
[ ! -e "$T/stuck.vgrid" ] || { echo "FAIL failed brick left a manifest"; fails=$((fails + 1)); }
[ -z "$(find "$T/stuck.bricks" -type f 2>/dev/null)" ] || { echo "FAIL failed set left files"; fails=$((fails + 1)); }

# Issue 23: a rerun that fails late or is interrupted leaves the old set whole (vox-info reads it as before) and no
# file of its own; a rerun that succeeds replaces it and removes the old set's files.
files_of() { (cd "$T" && find "$1.vgrid" "$1.bricks" -type f 2>/dev/null | sort); }
check "old set" 0 "$V" "$S/bunny_1k.obj" -o "$T/rr.vgrid" --res 20 --bricks 3 3 3 -q
check "old set info" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
mv "$T/out" "$T/rr.json"
files_of rr >"$T/rr.files"
check "rerun fails late" 3 late_failure "$T/rr.vgrid"
same "old set's files after a failed rerun" "$T/rr.files" <(files_of rr)
check "old set after a failed rerun" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
same "old set reads as before after a failed rerun" "$T/rr.json" "$T/out"
# Interrupted once it has written bricks (SIGINT, as Ctrl-C): exit 130, the old set whole, nothing of the new one.
# Job control on: a background job of a script otherwise starts with SIGINT ignored, which the tools respect.
set -m
"$V" "$SEED/meshes/bun_zipper.ply" -o "$T/rr.vgrid" --res 400 --bricks 8 8 8 -q 2>"$T/err" &
pid=$!
set +m
for _ in $(seq 400); do
  [ -n "$(find "$T/rr.bricks" -mindepth 2 -name 'b_*' 2>/dev/null | grep -v -F -f "$T/rr.files")" ] && break
  sleep 0.05
done
kill -INT $pid
wait $pid
code=$?
[ $code = 130 ] || { echo "FAIL interrupted rerun: exit $code, expected 130"; cat "$T/err"; fails=$((fails + 1)); }
same "old set's files after an interrupted rerun" "$T/rr.files" <(files_of rr)
check "old set after an interrupted rerun" 0 "$I" "$T/rr.vgrid" --json --cells --primitives
same "old set reads as before after an interrupted rerun" "$T/rr.json" "$T/out"
check "rerun succeeds" 0 "$V" "$S/bunny_1k.obj" -o "$T/rr.vgrid" --res 24 --bricks 5 5 5 -q
[ -z "$(comm -12 "$T/rr.files" <(files_of rr) | grep -v '^rr.vgrid$')" ] ||
  { echo "FAIL a replaced set's files stayed"; fails=$((fails + 1)); }
check "rerun as a single grid" 0 "$V" "$S/bunny_1k.obj" -o "$T/rr.vgrid" --res 24 -q
[ "$(files_of rr)" = rr.vgrid ] || { echo "FAIL a set replaced by a grid file left files"; files_of rr; fails=$((fails + 1)); }

# Two outputs in one folder whose names share a stem (both under s2.bricks/) never share a file.
check "first of two" 0 "$V" "$S/bunny_1k.obj" -o "$T/s2.vgrid" --res 20 --bricks 2 2 2 -q
check "first of two info" 0 "$I" "$T/s2.vgrid" --json --cells
mv "$T/out" "$T/s2.json"
check "second of two" 0 "$V" "$S/scene5_01_sphere.txt" -o "$T/s2.other" --grid 8 8 8 --bricks 2 2 2 -q
check "second of two again" 0 "$V" "$S/scene5_01_sphere.txt" -o "$T/s2.other" --grid 9 9 9 --bricks 2 2 2 -q
check "first of two still read" 0 "$I" "$T/s2.vgrid" --json --cells
same "first of two unchanged" "$T/s2.json" "$T/out"
check "second of two read" 0 "$I" "$T/s2.other" --json
# "-o foo.bricks": its brick folder would take the manifest's name; refused before any work.
check "set named like its folder" 3 "$V" "$S/scene5_01_sphere.txt" -o "$T/foo.bricks" --grid 8 8 8 --bricks 2 2 2
expect_err "set named like its folder" "foo.bricks: cannot write a grid set under this name"
[ ! -e "$T/foo.bricks" ] || { echo "FAIL refused set left files"; fails=$((fails + 1)); }
# A scene file replaced by a 2 GiB (sparse) file: refused by its size, before it is read.
check "set for a huge scene file" 0 "$V" "$S/scene5_01_sphere.txt" -o "$T/hs.vgrid" --grid 8 8 8 --bricks 2 2 2 -q
truncate -s 2G "$(gen hs)/scene.vgrid"
check "huge scene file" 2 timeout 10 "$I" "$T/hs.vgrid"
expect_err "huge scene file" "scene.vgrid: not the scene file .* names (size differs"

# Bad sets: one line naming the file, exit 2.
cp "$T/spheres_set.vgrid" "$T/bad.vgrid"
printf '\x01' | dd of="$T/bad.vgrid" bs=1 seek=40 conv=notrunc 2>/dev/null
check "corrupt manifest" 2 "$I" "$T/bad.vgrid"
expect_err "corrupt manifest" "bad.vgrid: byte .*checksum"
head -c 50 "$T/spheres_set.vgrid" >"$T/short.vgrid"
check "truncated manifest" 2 "$I" "$T/short.vgrid"
expect_err "truncated manifest" "short.vgrid: truncated"
first=$(ls "$(gen spheres_set)" | grep "^b_" | head -1)
mv "$(gen spheres_set)/$first" "$T/moved.vgrid"
check "missing brick" 2 "$TR" "$T/spheres_set.vgrid" -o "$T/m.png"
expect_err "missing brick" "$first"
[ ! -e "$T/m.png" ] || { echo "FAIL image written from a broken set"; fails=$((fails + 1)); }
cp "$T/squashed.vgrid" "$(gen spheres_set)/$first"  # another grid in its place
check "foreign brick" 2 "$E" "$T/spheres_set.vgrid" -o "$T/m.ply"
expect_err "foreign brick" "not the brick"
# The scene file, stored once: missing or another set's is named; a brick opened directly is named as one.
cp "$(gen plane_set)/scene.vgrid" "$(gen spheres_set)/scene.vgrid"
check "foreign scene file" 2 "$I" "$T/spheres_set.vgrid"
expect_err "foreign scene file" "spheres_set.bricks/g[0-9a-f]*/scene.vgrid: not the scene file"
rm "$(gen plane_set)/scene.vgrid"
check "missing scene file" 2 "$TR" "$T/plane_set.vgrid" -o "$T/m.png"
expect_err "missing scene file" "plane_set.bricks/g[0-9a-f]*/scene.vgrid"
check "brick opened directly" 2 "$I" "$(gen bbox_set)/$(ls "$(gen bbox_set)" | grep '^b_' | head -1)"
expect_err "brick opened directly" "a brick of a grid set"

echo "grid_set.sh: $passes passed, $fails failed"
[ $fails = 0 ]
