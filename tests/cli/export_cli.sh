#!/usr/bin/env bash
# vox-export end to end: every format and face mode, --stats on stderr only, and the STYLE.md exit codes for bad
# input (2), an unknown output extension (1, a usage error) and an unwritable output (3), with nothing left behind.
# Usage: export_cli.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
export_tool=$build/vox-export
voxelize=$build/vox-voxelize
[ -x "$export_tool" ] || { echo "missing $export_tool"; exit 1; }
[ -x "$voxelize" ] || { echo "SKIP: vox-voxelize not built"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Exit code of a command, its stderr in $tmp/err and stdout in $tmp/out.
run() { "$@" >"$tmp/out" 2>"$tmp/err"; echo $?; }
expect_code() {  # expect_code CODE DESCRIPTION COMMAND...
  local want=$1 what=$2; shift 2
  local got; got=$(run "$@")
  [ "$got" = "$want" ] || fail "$what: exit $got, expected $want ($(head -c 300 "$tmp/err"))"
}
# No temporary files next to the outputs.
expect_clean() { local left; left=$(find "$1" -maxdepth 1 -name '.*tmp*' | head -1); [ -z "$left" ] || fail "left behind: $left"; }

# Two unit cubes apart and an L of triangles: small, with holes between them.
{ cat "$src/tests/data/unit_cube.obj"; cat <<'OBJ'
v 2 0 0
v 3 0 0
v 3 2 1
f 9 10 11
OBJ
} >"$tmp/scene.obj"
expect_code 0 "voxelize" "$voxelize" "$tmp/scene.obj" -o "$tmp/g.vgrid" --grid 12 8 4 --quiet

for faces in all exposed merged; do
  for ext in ply obj off stl glb gltf; do
    out="$tmp/m_$faces.$ext"
    expect_code 0 "export $faces $ext" "$export_tool" "$tmp/g.vgrid" -o "$out" --faces "$faces" --quiet
    [ -s "$out" ] || fail "$out missing or empty"
    [ -s "$tmp/out" ] && fail "export $faces $ext printed on stdout"
  done
done
head -c 200 "$tmp/m_exposed.ply" | grep -q "format binary_little_endian" || fail "PLY not binary by default"
head -c 300 "$tmp/m_exposed.ply" | grep -q "property uchar red" || fail "PLY without face colours"
expect_code 0 "ascii ply" "$export_tool" "$tmp/g.vgrid" -o "$tmp/a.ply" --ascii --color none --quiet
head -c 200 "$tmp/a.ply" | grep -q "format ascii" || fail "--ascii PLY not ASCII"
grep -q "red" "$tmp/a.ply" && fail "--color none wrote colours"
# OBJ colours: shared vertices, faces grouped by usemtl, materials in a .mtl beside the .obj (issue 10).
grep -qx 'mtllib m_exposed.mtl' "$tmp/m_exposed.obj" || fail "OBJ without mtllib m_exposed.mtl"
grep -q '^usemtl vox_' "$tmp/m_exposed.obj" || fail "OBJ without usemtl"
grep -q '^Kd ' "$tmp/m_exposed.mtl" 2>/dev/null || fail "no materials in m_exposed.mtl"
head -c 4 "$tmp/m_exposed.off" | grep -qx 'OFF' || fail "OFF header is not OFF: $(head -1 "$tmp/m_exposed.off")"
expect_code 0 "material colours" "$export_tool" "$tmp/g.vgrid" -o "$tmp/mat.ply" --color material --threads 1 --quiet

# --stats: name: value lines on stderr, nothing on stdout.
expect_code 0 "stats" "$export_tool" "$tmp/g.vgrid" -o "$tmp/s.ply" --faces merged --stats
for key in voxels vertices faces exposed_faces merged_faces merged_over_exposed; do
  grep -q "^$key: " "$tmp/err" || fail "--stats lacks $key"
done
[ -s "$tmp/out" ] && fail "--stats wrote to stdout"
merged=$(sed -n 's/^merged_faces: //p' "$tmp/err"); exposed=$(sed -n 's/^exposed_faces: //p' "$tmp/err")
[ "${merged:-1}" -le "${exposed:-0}" ] || fail "merged_faces $merged > exposed_faces $exposed"

expect_code 0 "help" "$export_tool" --help
grep -q -- "--faces" "$tmp/out" || fail "--help does not list --faces"
grep -q "majority" "$tmp/out" || fail "--help does not say how material colours are chosen"
expect_code 0 "version" "$export_tool" --version
expect_code 1 "bad --faces" "$export_tool" "$tmp/g.vgrid" -o "$tmp/x.ply" --faces some
expect_code 1 "missing output" "$export_tool" "$tmp/g.vgrid"

# Bad input: a truncated and a corrupted grid file -> exit 2, one line, no output.
head -c 100 "$tmp/g.vgrid" >"$tmp/trunc.vgrid"
expect_code 2 "truncated grid" "$export_tool" "$tmp/trunc.vgrid" -o "$tmp/bad1.ply"
[ "$(wc -l <"$tmp/err")" = 1 ] || fail "truncated grid: error is not one line"
grep -q "^vox-export: error: " "$tmp/err" || fail "truncated grid: message lacks the tool prefix"
cp "$tmp/g.vgrid" "$tmp/flip.vgrid"
size=$(stat -c %s "$tmp/flip.vgrid")
printf '\xff\xff\xff\xff' | dd of="$tmp/flip.vgrid" bs=1 seek=$((size / 2)) conv=notrunc status=none
expect_code 2 "corrupt grid" "$export_tool" "$tmp/flip.vgrid" -o "$tmp/bad2.ply"
expect_code 2 "missing grid" "$export_tool" "$tmp/none.vgrid" -o "$tmp/bad3.ply"
printf 'not a grid' >"$tmp/text.vgrid"
expect_code 2 "not a grid" "$export_tool" "$tmp/text.vgrid" -o "$tmp/bad4.ply"
for f in bad1 bad2 bad3 bad4; do [ -e "$tmp/$f.ply" ] && fail "$f.ply written for bad input"; done

# Unknown output extension: a usage error, exit 1, before reading the grid.
expect_code 1 "unknown extension" "$export_tool" "$tmp/g.vgrid" -o "$tmp/mesh.xyz"
[ -e "$tmp/mesh.xyz" ] && fail "mesh.xyz written"

# Unwritable outputs: exit 3.
expect_code 3 "missing folder" "$export_tool" "$tmp/g.vgrid" -o "$tmp/no/such/dir/m.ply"
touch "$tmp/plainfile"
expect_code 3 "folder is a file" "$export_tool" "$tmp/g.vgrid" -o "$tmp/plainfile/m.ply"
mkdir "$tmp/ro" && chmod 555 "$tmp/ro"
if [ "$(id -u)" != 0 ]; then
  expect_code 3 "read-only folder" "$export_tool" "$tmp/g.vgrid" -o "$tmp/ro/m.ply"
  [ -z "$(ls -A "$tmp/ro")" ] || fail "read-only folder not empty"
fi
# /proc refuses new files even to root.
expect_code 3 "unwritable filesystem" "$export_tool" "$tmp/g.vgrid" -o /proc/vox_export_test.ply
chmod 755 "$tmp/ro"
expect_clean "$tmp"

if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_cli: all checks passed"
