#!/usr/bin/env bash
# Voxel formats of vox-export (issue 11): .binvox, MagicaVoxel .vox and OpenVDB .vdb, each read back by a reader
# that knows only the published format (tests/clients/voxel_readers.py: binvox and .vox written from the format
# descriptions; .vdb through OpenVDB's own pyopenvdb), and the .vdb imported by Blender as a volume
# (tests/clients/blender_volume.py). Checks, on a filled closed cube (solid cells), a scene of two materials and the
# 69k-triangle Stanford bunny (release builds only):
#  - each file holds exactly occupied_cells + solid_cells voxels of vox-info, every occupied cell among them, and
#    the three formats hold the same cell set;
#  - .vox: several models when the grid is wider than 256 cells; the two materials give two colours;
#  - .vdb: grids density and count; Blender loads both as a volume object whose voxel size and origin are the
#    grid's cell size and first cell centre;
#  - exit codes: an output folder that does not exist (3), a corrupt grid (2); nothing left behind.
# pyopenvdb and Blender are optional (skipped with a note when missing; CI installs them: install-deps.sh --clients).
# Usage: export_voxel_formats.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$(cd "$2" && pwd)
[ -x "$build/vox-voxelize" ] && [ -x "$build/vox-export" ] && [ -x "$build/vox-info" ] ||
  { echo "SKIP: tools not built"; exit 0; }
py=/usr/bin/python3  # Debian's python3-openvdb installs pyopenvdb for the system Python only
readers=$src/tests/clients/voxel_readers.py
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
has_vdb=1
$py -c 'import pyopenvdb' 2>/dev/null || { has_vdb=0; echo "note: pyopenvdb missing, .vdb not read back"; }
sanitized=$(grep -s '^VOX_SANITIZE:BOOL=ON' "$build/CMakeCache.txt")

"$build/vox-voxelize" "$src/tests/data/unit_cube.obj" -o "$tmp/cube.vgrid" --grid 20 18 16 --fill --quiet ||
  fail "voxelize cube"
"$build/vox-voxelize" "$src/tests/data/two_materials.obj" -o "$tmp/two.vgrid" --grid 300 12 10 --quiet ||
  fail "voxelize two_materials"
grids="cube two"
bunny=${VOX_SEED_DIR:-$src/../shared/seed-scenes}/meshes/bun_zipper.ply
if [ -z "$sanitized" ] && [ -f "$bunny" ]; then
  "$build/vox-voxelize" "$bunny" -o "$tmp/bunny.vgrid" --res 160 --fill --quiet || fail "voxelize bunny"
  grids="$grids bunny"
fi

vdbs=()
for g in $grids; do
  "$build/vox-info" "$tmp/$g.vgrid" --json --cells >"$tmp/$g.json" || { fail "vox-info $g"; continue; }
  files=()
  for ext in binvox vox vdb; do
    out=$tmp/$g.$ext
    "$build/vox-export" "$tmp/$g.vgrid" -o "$out" --color material --quiet >"$tmp/stdout" 2>"$tmp/stderr" ||
      { fail "export $g.$ext: $(head -c 300 "$tmp/stderr")"; continue; }
    [ -s "$tmp/stdout" ] && fail "export $g.$ext printed on stdout"
    [ -s "$tmp/stderr" ] && fail "export $g.$ext --quiet printed: $(head -c 200 "$tmp/stderr")"
    [ "$ext" = vdb ] && { vdbs+=("$out"); [ "$has_vdb" = 1 ] || continue; }
    files+=("$out")
  done
  $py "$readers" "$tmp/$g.json" "${files[@]}" >"$tmp/$g.read" 2>&1 || fail "$g read back: $(grep -v RESULT "$tmp/$g.read" | tail -3)"
  sed -n 's|^RESULT [^ ]*/|  |p' "$tmp/$g.read"
  cmp -s "$tmp/$g.binvox.cells" "$tmp/$g.vox.cells" || fail "$g: binvox and .vox hold different cells"
  [ "$has_vdb" = 1 ] && { cmp -s "$tmp/$g.vox.cells" "$tmp/$g.vdb.cells" || fail "$g: .vox and .vdb differ"; }
done
grep -q 'two.vox .* models=[2-9]' "$tmp/two.read" || fail "two.vox (300 cells wide) is not split into models"
grep -q 'two.vox .* colors=[2-9]' "$tmp/two.read" || fail "two.vox does not have the material colours"
# The warning for non-cubic cells, and none for cubic ones.
"$build/vox-export" "$tmp/cube.vgrid" -o "$tmp/w.binvox" 2>"$tmp/stderr" || fail "export w.binvox"
grep -q "warning: .*binvox voxels are cubes" "$tmp/stderr" || fail "no warning for the cube's non-cubic cells"
"$build/vox-voxelize" "$src/tests/data/unit_cube.obj" -o "$tmp/cubic.vgrid" --grid 8 8 8 --quiet
"$build/vox-export" "$tmp/cubic.vgrid" -o "$tmp/c.binvox" 2>"$tmp/stderr" || fail "export c.binvox"
[ -s "$tmp/stderr" ] && fail "warning for cubic cells: $(cat "$tmp/stderr")"

# Exit codes and leftovers.
"$build/vox-export" "$tmp/cube.vgrid" -o "$tmp/missing/x.vox" 2>"$tmp/stderr"
[ $? = 3 ] || fail "output in a missing folder: not exit 3"
head -c 100 "$tmp/cube.vgrid" >"$tmp/bad.vgrid"
"$build/vox-export" "$tmp/bad.vgrid" -o "$tmp/bad.vdb" 2>"$tmp/stderr"
[ $? = 2 ] || fail "truncated grid: not exit 2"
[ "$(wc -l <"$tmp/stderr")" = 1 ] || fail "truncated grid: not one line: $(cat "$tmp/stderr")"
left=$(find "$tmp" -name '.*tmp*' | head -1)
[ -z "$left" ] || fail "left behind: $left"

# Blender: each .vdb a volume object with both grids, voxel size and origin those of the grid (not under the
# sanitizers: Blender is not ours, and the release run already covers it).
if command -v blender >/dev/null && [ -z "$sanitized" ]; then
  (cd "$tmp" && timeout 300 blender -b --factory-startup --python "$src/tests/clients/blender_volume.py" -- \
    "${vdbs[@]}") >"$tmp/blender.log" 2>&1
  for vdb in "${vdbs[@]}"; do
    g=$(basename "$vdb" .vdb)
    line=$(grep -m1 "^RESULT $vdb " "$tmp/blender.log")
    [ -n "$line" ] || { fail "$g.vdb: Blender printed no result ($(tail -2 "$tmp/blender.log" | tr '\n' ' '))"; continue; }
    echo "  blender $g.vdb: $(echo "$line" | cut -d' ' -f3-)"
    val() { echo "$line" | grep -o " $1=[^ ]*" | cut -d= -f2; }
    [ "$(val objects)" = 1 ] && [ "$(val grids)" = density,count ] && [ "$(val loaded)" = 1 ] ||
      fail "$g.vdb: Blender did not load density and count as one volume: $line"
    # Expected voxel size and first cell centre, from vox-info's bounds and dims (float precision in Blender).
    $py - "$tmp/$g.json" "$(val scale)" "$(val translate)" <<'PY' || fail "$g.vdb: Blender's voxel transform is wrong"
import json, sys
g = json.load(open(sys.argv[1]))
lo, hi, n = g["bounds"]["min"], g["bounds"]["max"], g["dims"]
scale = [float(x) for x in sys.argv[2].split(",")]
translate = [float(x) for x in sys.argv[3].split(",")]
for a in range(3):
    side = (hi[a] - lo[a]) / n[a]
    assert abs(scale[a] - side) <= 1e-6 * side, (a, scale[a], side)
    assert abs(translate[a] - (lo[a] + 0.5 * side)) <= 1e-6 * max(1, abs(lo[a])), (a, translate[a])
PY
  done
elif [ -z "$sanitized" ]; then
  echo "note: blender missing, .vdb not imported"
fi

if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_voxel_formats: binvox, .vox and .vdb hold exactly the grids' voxels ($grids)"
