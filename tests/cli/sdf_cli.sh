#!/usr/bin/env bash
# vox-voxelize --sdf (issue 38): the band stored in the grid file and reported by vox-info, its values read back by
# numpy from vox-export's .npz and by OpenVDB's own pyopenvdb from the .vdb level set `surface`, equal to the grid
# file's as the formats round them; bad half-widths, --bricks, and non-cubic cells for a level set each refused
# with one line, nothing written.
# Usage: sdf_cli.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
py=/usr/bin/python3  # Debian's numpy and pyopenvdb are the system Python's
cube=$src/tests/data/unit_cube.obj

"$build/vox-voxelize" "$cube" -o "$tmp/c.vgrid" --res 10 --sdf 2>"$tmp/err" -q || fail "voxelize --sdf: $(cat "$tmp/err")"
"$build/vox-info" "$tmp/c.vgrid" >"$tmp/info" || fail "vox-info"
grep -q '^distance_band: [1-9][0-9]* cells within 3 cell widths, signed distances -' "$tmp/info" ||
  fail "vox-info: $(grep distance "$tmp/info")"
"$build/vox-voxelize" "$cube" -o "$tmp/c2.vgrid" --res 10 --sdf 1.5 -q || fail "--sdf 1.5"
grep -q 'within 1.5 cell widths' <("$build/vox-info" "$tmp/c2.vgrid") || fail "--sdf 1.5 not stored"

"$build/vox-export" "$tmp/c.vgrid" -o "$tmp/c.npz" -q || fail "export .npz"
"$build/vox-export" "$tmp/c.vgrid" -o "$tmp/c.vdb" -q || fail "export .vdb"
"$build/vox-info" "$tmp/c.vgrid" --json --cells >"$tmp/info.json"
# The unit cube [0, 1]^3 in cubic cells: every band value is the distance from its cell's centre to the cube's
# surface, negative inside; the .vdb holds the same values as floats.
$py - "$tmp" <<'PY' || fail "numpy/pyopenvdb read-back"
import sys, numpy as np
tmp = sys.argv[1]
z = np.load(tmp + "/c.npz")
for name in ("occupancy", "solid", "sdf", "bounds", "dims", "transform"):
    assert name in z.files, name
sdf, dims, t = z["sdf"], z["dims"], z["transform"]
assert sdf.shape == tuple(dims), (sdf.shape, dims)
band = np.argwhere(np.isfinite(sdf))
assert len(band) > 0
centres = band @ t[:3, :3].T + t[:3, 3]
inside = np.all((centres > 0) & (centres < 1), axis=1)
outside_d = np.linalg.norm(np.maximum(np.maximum(-centres, centres - 1), 0), axis=1)
inside_d = np.min(np.minimum(centres, 1 - centres), axis=1)
expected = np.where(inside, -inside_d, outside_d)
assert np.max(np.abs(sdf[tuple(band.T)] - expected)) < 1e-12, np.max(np.abs(sdf[tuple(band.T)] - expected))
assert (z["occupancy"].sum() > 0)
try:
    import pyopenvdb as vdb
except ImportError:
    print("note: pyopenvdb missing, .vdb not read back"); sys.exit(0)
g = vdb.read(tmp + "/c.vdb", "surface")
assert g.gridClass == "level set", g.gridClass
h = t[0, 0]
assert abs(g.background - 3 * h) < 1e-6 * h, (g.background, h)
assert g.activeVoxelCount() == len(band), (g.activeVoxelCount(), len(band))
acc = g.getConstAccessor()
for (i, j, k) in band[:: max(1, len(band) // 200)]:
    v, on = acc.probeValue((int(i), int(j), int(k)))
    assert on and v == np.float32(sdf[i, j, k]), (i, j, k, v, sdf[i, j, k])
PY

# Refusals: one line each, exit 1 (usage), no output left behind.
for bad in 0 -1 65 nan x; do
  rm -f "$tmp/bad.vgrid"
  "$build/vox-voxelize" "$cube" -o "$tmp/bad.vgrid" --res 8 --sdf "$bad" 2>"$tmp/err"
  code=$?
  [ "$code" = 1 ] || fail "--sdf $bad: exit $code"
  [ "$(wc -l <"$tmp/err")" = 1 ] || fail "--sdf $bad: $(cat "$tmp/err")"
  [ ! -e "$tmp/bad.vgrid" ] || fail "--sdf $bad: output written"
done
"$build/vox-voxelize" "$cube" -o "$tmp/set.vgrid" --res 8 --sdf --bricks 2 2 2 2>"$tmp/err"
[ $? = 1 ] && grep -q 'grid sets' "$tmp/err" || fail "--sdf --bricks: $(cat "$tmp/err")"
"$build/vox-voxelize" "$cube" -o "$tmp/flat.vgrid" --grid 4 4 8 --sdf -q || fail "--grid 4 4 8 --sdf"
"$build/vox-export" "$tmp/flat.vgrid" -o "$tmp/flat.vdb" 2>"$tmp/err"
[ $? = 1 ] && grep -q 'cubic cells' "$tmp/err" && [ ! -e "$tmp/flat.vdb" ] || fail "non-cubic level set: $(cat "$tmp/err")"
"$build/vox-export" "$tmp/flat.vgrid" -o "$tmp/flat.npz" -q || fail "non-cubic .npz"

# --fraction (implies --fill): a box of volume 0.34 * 0.5 * 0.62 whose faces cut cells, so most boundary fractions
# are strictly between 0 and 1. vox-info's total, the .npz's fraction (1 on solid cells) times cell volumes, and the
# .vdb's density grid all give the box's volume.
printf 'v 0.13 0.21 0.05\nv 0.47 0.21 0.05\nv 0.47 0.71 0.05\nv 0.13 0.71 0.05\nv 0.13 0.21 0.67\nv 0.47 0.21 0.67\nv 0.47 0.71 0.67\nv 0.13 0.71 0.67\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n' >"$tmp/box.obj"
"$build/vox-voxelize" "$tmp/box.obj" -o "$tmp/f.vgrid" --grid 7 9 8 --bounds 0 0 0 0.7 0.9 0.8 --fraction -q \
  2>"$tmp/err" || fail "--fraction: $(cat "$tmp/err")"
"$build/vox-info" "$tmp/f.vgrid" >"$tmp/info" || fail "vox-info --fraction"
grep -Eq '^fraction_volume: 0\.105(4|39999)' "$tmp/info" || fail "vox-info: $(grep fraction "$tmp/info")"
"$build/vox-export" "$tmp/f.vgrid" -o "$tmp/f.npz" -q || fail "export fractions .npz"
"$build/vox-export" "$tmp/f.vgrid" -o "$tmp/f.vdb" -q || fail "export fractions .vdb"
$py - "$tmp" <<'PY' || fail "fractions read back"
import sys, numpy as np
tmp = sys.argv[1]
z = np.load(tmp + "/f.npz")
f, solid, occ = z["fraction"], z["solid"], z["occupancy"]
assert f.shape == (7, 9, 8), f.shape
assert np.all((f >= 0) & (f <= 1)) and np.all(f[solid.astype(bool)] == 1)
assert np.count_nonzero((f > 0) & (f < 1)) > 50, np.count_nonzero((f > 0) & (f < 1))
exact = 0.34 * 0.5 * 0.62
total = f.sum() * 0.1 ** 3
assert abs(total - exact) < 1e-12 * exact, (total, exact)
try:
    import pyopenvdb as vdb
except ImportError:
    sys.exit(0)
acc = vdb.read(tmp + "/f.vdb", "density").getConstAccessor()
for (i, j, k) in np.argwhere(occ):
    v, on = acc.probeValue((int(i), int(j), int(k)))
    assert v == np.float32(f[i, j, k]), (i, j, k, v, f[i, j, k])
PY
# An open mesh has no exact volume: refused with one line, nothing written.
head -n 18 "$tmp/box.obj" >"$tmp/open.obj"
"$build/vox-voxelize" "$tmp/open.obj" -o "$tmp/open.vgrid" --res 8 --fraction 2>"$tmp/err"
[ $? = 1 ] && [ ! -e "$tmp/open.vgrid" ] && grep -q 'open edges' "$tmp/err" && [ "$(wc -l <"$tmp/err")" = 1 ] ||
  fail "--fraction of an open mesh: $(cat "$tmp/err")"

# Issue 45: a half-width just above the limit is printed as given (not "64", which reads as inside (0, 64]).
"$build/vox-voxelize" "$cube" -o "$tmp/bad.vgrid" --res 8 --sdf 64.0000001 2>"$tmp/err"
[ $? = 1 ] && grep -q 'half-width 64.0000001 must be a number in (0, 64]' "$tmp/err" ||
  fail "--sdf 64.0000001: $(cat "$tmp/err")"
# --sdf before the scene: a path is not a number, so it is the scene, and the band is the default 3 cells.
"$build/vox-voxelize" --sdf "$cube" -o "$tmp/first.vgrid" --res 8 -q 2>"$tmp/err" || fail "--sdf SCENE: $(cat "$tmp/err")"
grep -q 'within 3 cell widths' <("$build/vox-info" "$tmp/first.vgrid") || fail "--sdf SCENE: no default band"
"$build/vox-voxelize" --sdf 2 "$cube" -o "$tmp/first2.vgrid" --res 8 -q 2>"$tmp/err" || fail "--sdf 2 SCENE: $(cat "$tmp/err")"
grep -q 'within 2 cell widths' <("$build/vox-info" "$tmp/first2.vgrid") || fail "--sdf 2 SCENE: not stored"
"$build/vox-voxelize" "$cube" -o "$tmp/bad.vgrid" --sdf x --res 8 2>"$tmp/err"  # a scene given: x is a bad HALF
[ $? = 1 ] && grep -q 'HALF x is not a number' "$tmp/err" && [ ! -e "$tmp/bad.vgrid" ] || fail "SCENE --sdf x: $(cat "$tmp/err")"
# An inside-out cube: its fractions count the solid it encloses (1), its signed volume is -1; vox-info says why.
awk '/^f /{print "f", $4, $3, $2; next} {print}' "$tmp/box.obj" >"$tmp/inward.obj"
"$build/vox-voxelize" "$tmp/inward.obj" -o "$tmp/inward.vgrid" --res 8 --fraction -q 2>"$tmp/err" ||
  fail "--fraction of an inward box: $(cat "$tmp/err")"
"$build/vox-info" "$tmp/inward.vgrid" >"$tmp/info"
grep -q '^fraction_volume: 0.105.*(the scene.s own volume: -0.105.*; its triangles face inward' "$tmp/info" ||
  fail "vox-info of an inward box: $(grep fraction "$tmp/info")"
grep -q '"mesh_faces_inward": true' <("$build/vox-info" "$tmp/inward.vgrid" --json) || fail "vox-info --json inward"
grep -q '"mesh_faces_inward": false' <("$build/vox-info" "$tmp/f.vgrid" --json) || fail "vox-info --json outward"

# A scene with a plane: distances leave it out and say so.
"$build/vox-voxelize" "$src/data/6837/scenes/scene2_06_plane.txt" -o "$tmp/p.vgrid" --res 8 --sdf 2>"$tmp/err" ||
  fail "plane scene: $(cat "$tmp/err")"
grep -q 'planes are left out of the signed distances' "$tmp/err" || fail "plane scene: no note: $(cat "$tmp/err")"

[ "$failures" = 0 ] && echo "sdf_cli: all passed"
exit "$failures"
