#!/usr/bin/env bash
# vox-voxelize --fill says how it decided (issue 11): "closed surface" for closed meshes, the winding number with the
# open-edge count for open ones (the scanned Stanford bunny fills, it once filled nothing silently), a warning when
# nothing is filled, nothing with --quiet; vox-info counts the solid cells.
# Usage: fill_cli.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
voxelize=$build/vox-voxelize
info=$build/vox-info
[ -x "$voxelize" ] || { echo "missing $voxelize"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
res=48
grep -qs '^VOX_SANITIZE:BOOL=ON' "$build/CMakeCache.txt" && res=20

# fill_line SCENE ARGS...: runs vox-voxelize --fill into $tmp/g.vgrid; its stderr in $tmp/err.
fill_line() {
  local scene=$1; shift
  "$voxelize" "$scene" -o "$tmp/g.vgrid" --fill "$@" 2>"$tmp/err" || fail "$scene: exit $? ($(head -c 300 "$tmp/err"))"
}
solid() { "$info" "$tmp/g.vgrid" --json | grep -o '"solid_cells": [0-9]*' | grep -o '[0-9]*$'; }

fill_line "$src/tests/data/unit_cube.obj" --bounds -0.25 -0.25 -0.25 1.25 1.25 1.25 --grid 12 12 12
grep -q '^vox-voxelize: fill: closed surface, 216 solid cells$' "$tmp/err" || fail "cube: $(cat "$tmp/err")"
[ "$(solid)" = 216 ] || fail "cube: vox-info solid_cells $(solid)"

# The cube without its top face (z = 1): a large hole of 4 open edges, filled by winding number.
grep -v "^f 5 " "$src/tests/data/unit_cube.obj" >"$tmp/open.obj"
fill_line "$tmp/open.obj" --bounds -0.25 -0.25 -0.25 1.25 1.25 1.25 --grid 12 12 12
grep -q '^vox-voxelize: fill: |winding number| >= 0.5 (mesh has 4 open edges), [1-9][0-9]* solid cells' "$tmp/err" ||
  fail "open cube: $(cat "$tmp/err")"
# The closed cube's 6x6x6 interior cells, and the layer under the missing face (no longer occupied) where the
# winding number is about 0.6; the layer above the hole (about 0.4) stays out.
[ "$(solid)" = 252 ] || fail "open cube: $(solid) solid cells, expected 6 x 6 x 7 = 252"

bunny=${VOX_SEED_DIR:-$src/data}/meshes/bun_zipper.ply
if [ -f "$bunny" ]; then
  fill_line "$bunny" --res "$res"
  want='^vox-voxelize: fill: |winding number| >= 0.5 (mesh has 223 open edges), [1-9][0-9]* solid cells'
  grep -q "$want" "$tmp/err" ||
    fail "scanned bunny: $(cat "$tmp/err")"
  [ "$(solid)" -gt 0 ] || fail "scanned bunny: no solid cell"
fi

# Bounds inside the cube: no surface cell, but the surfaces outside the bounds count (issue 45): every cell solid.
fill_line "$src/tests/data/unit_cube.obj" --bounds 0.4 0.4 0.4 0.6 0.6 0.6 --grid 4 4 4
grep -q '^vox-voxelize: fill: |winding number| >= 0.5 (the bounds cut the scene), 64 solid cells' "$tmp/err" ||
  fail "bounds inside: $(cat "$tmp/err")"
[ "$(solid)" = 64 ] || fail "bounds inside: vox-info solid_cells $(solid)"
# Bounds beside the cube: nothing inside, said, not silent.
fill_line "$src/tests/data/unit_cube.obj" --bounds 1.4 0.4 0.4 1.6 0.6 0.6 --grid 4 4 4
grep -q 'warning: .*unit_cube.obj: fill: no empty cell is inside a surface: nothing filled' "$tmp/err" ||
  fail "nothing filled: $(cat "$tmp/err")"

fill_line "$tmp/open.obj" --grid 8 8 8 --quiet
[ -s "$tmp/err" ] && fail "--quiet: $(cat "$tmp/err")"

[ "$failures" = 0 ] && echo "fill_cli: ok"
exit $((failures > 0))
