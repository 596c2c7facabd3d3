#!/usr/bin/env bash
# The numeric domain of --sdf and --fraction (issue 45, docs/limits.md "Numeric domain"): a cube of side 1.3e154
# and 1e300 writes a band that vox-info and vox-export read (it once held keys past the grid, exit 0 on a file
# vox-info refused, and a heap overflow in .npz); a unit cube moved to 1e16 (cells narrower than the doubles'
# spacing) is refused with one line, exit 2, nothing written.
# Usage: numeric_domain.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

cube() {  # cube SIDE OFFSET > OBJ: [OFFSET, OFFSET + SIDE]^3, outward
  awk -v s="$1" -v o="$2" 'BEGIN {
    for (z = 0; z < 2; z++) for (y = 0; y < 2; y++) for (x = 0; x < 2; x++)
      printf "v %.17g %.17g %.17g\n", o + x * s, o + y * s, o + z * s
    print "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6"
  }'
}

for side in 1.3e154 1e300; do
  cube "$side" 0 >"$tmp/c.obj"
  "$build/vox-voxelize" "$tmp/c.obj" -o "$tmp/c.vgrid" --res 8 --sdf 3 -q 2>"$tmp/err" || fail "$side: $(cat "$tmp/err")"
  "$build/vox-info" "$tmp/c.vgrid" >"$tmp/info" 2>"$tmp/err" || fail "$side: vox-info: $(cat "$tmp/err")"
  grep -q '^distance_band: [1-9][0-9]* cells within 3 cell widths' "$tmp/info" || fail "$side: $(grep distance "$tmp/info")"
  "$build/vox-export" "$tmp/c.vgrid" -o "$tmp/c.npz" -q 2>"$tmp/err" || fail "$side: export .npz: $(cat "$tmp/err")"
  [ "$(ls -A "$tmp" | grep -c '^\.')" = 0 ] || fail "$side: temporary files left: $(ls -A "$tmp")"
done

# The issue's unit cube moved to 1e16: 1e16 + 1 rounds to 1e16, so the cube is a point; its grid's cells (4 wide)
# are wider than the doubles' spacing (2): answered (no volume, distances to the point), and vox-info reads it.
cube 1 1e16 >"$tmp/point.obj"
"$build/vox-voxelize" "$tmp/point.obj" -o "$tmp/point.vgrid" --res 4 --sdf --fraction -q 2>"$tmp/err" ||
  fail "the point at 1e16: $(cat "$tmp/err")"
"$build/vox-info" "$tmp/point.vgrid" >"$tmp/info" 2>"$tmp/err" || fail "the point at 1e16: vox-info: $(cat "$tmp/err")"
grep -q '^fraction_volume: 0 ' "$tmp/info" || fail "the point at 1e16: $(grep fraction "$tmp/info")"
# A cube of side 16 there in 64 cells: cells of 1/4 where doubles lie 2 apart.
cube 16 1e16 >"$tmp/far.obj"
for flag in --sdf --fraction; do
  "$build/vox-voxelize" "$tmp/far.obj" -o "$tmp/far.vgrid" --res 64 $flag -q 2>"$tmp/err"
  status=$?
  [ "$status" = 2 ] && [ ! -e "$tmp/far.vgrid" ] && [ "$(wc -l <"$tmp/err")" = 1 ] &&
    grep -q 'cells of 0.25 on axis x are narrower than the spacing 2 of doubles at 1e+16: cell boundaries 0 and 1 coincide' "$tmp/err" ||
    fail "$flag, side 16 at 1e16: exit $status: $(cat "$tmp/err")"
done

# A closed cube of side 1e150 with --fraction: its volume, 1e450, is beyond a double, so vox-info gives the volumes in
# cells (the probe of issue 45 saw "fraction_volume: inf (the scene's own volume: -nan)"); 1 keeps world units.
for side in 1e150 1; do
  cube "$side" 0 >"$tmp/v.obj"
  "$build/vox-voxelize" "$tmp/v.obj" -o "$tmp/v.vgrid" --grid 4 4 4 --fraction -q 2>"$tmp/err" || fail "$side: $(cat "$tmp/err")"
  "$build/vox-info" "$tmp/v.vgrid" >"$tmp/info" 2>"$tmp/err" || fail "$side fraction: vox-info: $(cat "$tmp/err")"
  want='^fraction_volume: 1 (the scene.s own volume: 1)$'
  [ "$side" = 1 ] || want='^fraction_volume: 64 cells (the scene.s own volume: 64 cells; in world units'
  grep -q "$want" "$tmp/info" || fail "$side fraction: $(grep fraction "$tmp/info")"
  "$build/vox-info" "$tmp/v.vgrid" --json >"$tmp/info" 2>"$tmp/err" || fail "$side fraction: vox-info --json"
  grep -qiE ': -?(inf|nan)' "$tmp/info" && fail "$side fraction: inf or nan in the JSON: $(grep fractions "$tmp/info")"
done

[ "$failures" = 0 ] && echo "numeric_domain: all passed"
exit "$failures"
