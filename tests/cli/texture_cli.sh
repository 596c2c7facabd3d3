#!/usr/bin/env bash
# Texture colours end to end (issue 11): the Duck voxelized and exported with --color material comes out yellow
# in PLY and OBJ (its texture reaches vox-export through the grid file alone), and a corrupt texture image is bad
# input (exit 2, one line naming the scene and the image), never a crash.
# Usage: texture_cli.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
seed=${VOX_SEED_DIR:-$src/data}/gltf
voxelize=$build/vox-voxelize
export_tool=$build/vox-export
[ -x "$voxelize" ] && [ -x "$export_tool" ] || { echo "SKIP: tools not built"; exit 0; }
[ -f "$seed/Duck/glTF/Duck.gltf" ] || { echo "SKIP: no seed scenes"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The scene's folder is copied so the grid file is read with the scene gone: vox-export sees only the grid.
cp -r "$seed/Duck/glTF" "$tmp/duck"
"$voxelize" "$tmp/duck/Duck.gltf" -o "$tmp/duck.vgrid" --res 24 --quiet || fail "voxelize the Duck: exit $?"
rm -rf "$tmp/duck"
"$export_tool" "$tmp/duck.vgrid" -o "$tmp/duck.ply" --faces exposed --color material --ascii --quiet ||
  fail "export PLY: exit $?"
# Share of faces whose colour is yellow (red high, green high but below red, blue low).
yellow=$(python3 - "$tmp/duck.ply" <<'PY'
import sys
lines = open(sys.argv[1]).read().split("\n")
h = lines.index("end_header")
nv = next(int(l.split()[2]) for l in lines if l.startswith("element vertex"))
nf = next(int(l.split()[2]) for l in lines if l.startswith("element face"))
faces = [tuple(map(int, l.split()[-3:])) for l in lines[h + 1 + nv:h + 1 + nv + nf]]
print(int(100 * sum(r > 230 and 150 < g < 240 and b < 40 for r, g, b in faces) / max(1, len(faces))))
PY
)
[ "${yellow:-0}" -ge 80 ] || fail "only ${yellow:-0}% of the Duck's faces are yellow"
"$export_tool" "$tmp/duck.vgrid" -o "$tmp/duck.obj" --faces merged --color material --quiet ||
  fail "export OBJ: exit $?"
grep -q '^usemtl vox_ff' "$tmp/duck.obj" || fail "OBJ without a yellow-ish material"

# A truncated texture image: bad input, one line naming the scene file and the image.
cp -r "$seed/BoxTextured/glTF" "$tmp/box"
head -c 1000 "$tmp/box/CesiumLogoFlat.png" >"$tmp/cut.png" && mv "$tmp/cut.png" "$tmp/box/CesiumLogoFlat.png"
"$voxelize" "$tmp/box/BoxTextured.gltf" -o "$tmp/box.vgrid" --quiet 2>"$tmp/err"
code=$?
[ "$code" = 2 ] || fail "truncated texture: exit $code, expected 2"
[ "$(grep -c 'error' "$tmp/err")" = 1 ] || fail "truncated texture: not one error line: $(cat "$tmp/err")"
grep -q 'BoxTextured.gltf: image 0' "$tmp/err" || fail "error does not name the scene and image: $(cat "$tmp/err")"
[ -e "$tmp/box.vgrid" ] && fail "a grid was written for a bad scene"

[ "$failures" = 0 ] && echo "texture_cli: all passed"
exit $((failures > 0))
