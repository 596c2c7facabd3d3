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
bunny=${VOX_SEED_DIR:-$src/data}/meshes/bun_zipper.ply
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

# Crafted grids of one solid run over many cells (issue 23), written here from docs/grid-format.md: every export
# answers or refuses (exit 2, one line naming the grid and the estimate) within seconds, whatever the cells' count.
# Before: 2^63 cells hung .vox and .vdb (over 40 s), the meshes said "vector::reserve"; 16384^3 hung .vox; 1024^3
# all solid took the meshes 14.6 GB and a minute. The budget is fixed so that the refusals do not depend on the machine.
$py - "$tmp" <<'PY'
import struct, sys
def checksum(p):
    M = (1 << 64) - 1
    h = 0x9E3779B97F4A7C15 ^ len(p)
    n = len(p) // 8
    for i in range(n):
        h = ((h ^ struct.unpack_from('<Q', p, 8 * i)[0]) * 0x100000001B3) & M
        h ^= h >> 29
    if len(p) % 8:
        h = ((h ^ int.from_bytes(p[8 * n:] + b'\0' * (8 - len(p) % 8), 'little')) * 0x100000001B3) & M
        h ^= h >> 32
    return h
def grid(n):  # no primitive, no occupied cell, one solid run over all n^3 cells
    p = struct.pack('<4Q', 0, 0, 0, 0) + b'\0' + struct.pack('<Q', 0) + struct.pack('<6d', 0, 0, 0, 0, 0, 0)
    p += struct.pack('<6d', 0, 0, 0, n, n, n) + struct.pack('<3IB', n, n, n, 0)
    p += struct.pack('<QQQQQ', 0, 1, 0, 0, 0) + struct.pack('<QQQ', 1, 0, n ** 3)
    return b'VOXGRID\n' + struct.pack('<IIQQ', 2, 0, len(p), checksum(p)) + p
for name, n in [('big', 1 << 21), ('g16k', 16384), ('g1024', 1024)]:
    open(f'{sys.argv[1]}/{name}.vgrid', 'wb').write(grid(n))
PY
"$build/vox-info" "$tmp/big.vgrid" | grep -q "9223372036854775808 cells" || fail "big.vgrid is not the 2^63-cell grid"
# crafted NAME EXT CODE PATTERN: exit CODE within 20 s (124: timed out); on exit 2 one stderr line naming the grid
# and matching PATTERN.
crafted() {
  local name=$1 ext=$2 code=$3 pattern=${4:-} got start micros
  start=${EPOCHREALTIME/./}
  VOX_MEMORY_LIMIT_MB=1024 timeout 20 "$build/vox-export" "$tmp/$name.vgrid" -o "$tmp/$name.$ext" --quiet \
    >"$tmp/stdout" 2>"$tmp/stderr"
  got=$?
  micros=$((${EPOCHREALTIME/./} - start))
  echo "  $name.vgrid -> .$ext: exit $got in $((micros / 1000)) ms: $(head -c 200 "$tmp/stderr")"
  [ "$got" = "$code" ] || { fail "$name.$ext: exit $got, expected $code (124: timed out)"; return; }
  [ "$micros" -lt 10000000 ] || fail "$name.$ext: took ${micros} us"
  if [ "$code" = 2 ]; then
    [ "$(wc -l <"$tmp/stderr")" = 1 ] || fail "$name.$ext: not one line: $(cat "$tmp/stderr")"
    grep -q "^vox-export: error: $tmp/$name.vgrid: $pattern" "$tmp/stderr" ||
      fail "$name.$ext: message does not name the grid and match '$pattern': $(cat "$tmp/stderr")"
    [ ! -e "$tmp/$name.$ext" ] || fail "$name.$ext: written although refused"
  fi
}
crafted big binvox 2 "binvox: the grid's 2097152 cells on its longest axis exceed"
crafted big vox 2 "vox: 9223372036854775808 (2^63) voxels need 2^64 bytes or more"
crafted big vdb 2 "vdb: the voxels need 134217728 root tiles"
crafted big ply 2 "voxel mesh: a list of 9223372036854775808 (2^63) voxels at 32 bytes each needs about 2^64 bytes or more"
crafted big stl 2 "voxel mesh: a list of 9223372036854775808 (2^63) voxels"
crafted g16k vox 2 "vox: 4398046511104 (2^42) voxels need at least 17592186044416 (2^44) bytes"
crafted g16k ply 2 "voxel mesh: a list of 4398046511104 (2^42) voxels"
crafted g16k vdb 0
crafted g1024 ply 2 "voxel mesh: a list of 1073741824 voxels at 32 bytes each needs about 32769 MiB, more than the 1024"
crafted g1024 stl 2 "voxel mesh: a list of 1073741824 voxels"
crafted g1024 obj 2 "voxel mesh: a list of 1073741824 voxels"
crafted g1024 vox 2 "vox: 1073741824 voxels need at least"
crafted g1024 vdb 0
crafted g1024 binvox 0
# The .vdb files hold every cell as root tiles (64 of 4096^3 at 16384^3, none of them leaves); binvox the whole cube.
if [ "$has_vdb" = 1 ]; then
  $py - "$tmp/g16k.vdb" "$tmp/g1024.vdb" <<'PY' || fail "crafted .vdb files do not hold every cell"
import sys, pyopenvdb as vdb
for path, n in zip(sys.argv[1:], (16384, 1024)):
    d = vdb.read(path, 'density')
    assert d.activeVoxelCount() == n ** 3, (path, d.activeVoxelCount())
    assert d.evalActiveVoxelBoundingBox() == ((0, 0, 0), (n - 1, n - 1, n - 1)), path
    assert d.leafCount() == 0, (path, d.leafCount())
PY
fi
[ "$(stat -c %s "$tmp/g1024.binvox" 2>/dev/null)" = $((2 * ((1 << 30) + 254) / 255 + $(grep -a -b -m1 '^data$' "$tmp/g1024.binvox" | cut -d: -f1) + 5)) ] ||
  fail "g1024.binvox does not have the size of 2^30 set bits"
rm -f "$tmp"/g1024.binvox "$tmp"/*.vdb
# An allocation that fails anyway (here the address space is limited below what the budget allows) is one line
# naming the grid and the output, exit 2, not "vector::reserve" or a bare "out of memory".
(ulimit -v 1500000; VOX_MEMORY_LIMIT_MB=100000 timeout 20 "$build/vox-export" "$tmp/g1024.vgrid" -o "$tmp/g1024.ply" \
  --quiet 2>"$tmp/stderr")
code=$?
if [ -z "$sanitized" ]; then  # ASan reserves terabytes of address space: no ulimit -v under the sanitizers
  [ "$code" = 2 ] || fail "out of memory: exit $code, expected 2: $(cat "$tmp/stderr")"
  grep -q "^vox-export: error: $tmp/g1024.vgrid: $tmp/g1024.ply: out of memory" "$tmp/stderr" ||
    fail "out of memory does not name the grid and the output: $(cat "$tmp/stderr")"
fi

if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_voxel_formats: binvox, .vox and .vdb hold exactly the grids' voxels ($grids)"
