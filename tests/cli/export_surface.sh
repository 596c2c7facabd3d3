#!/usr/bin/env bash
# vox-export --surface (issue 47) checked by real clients: MeshLab's "Compute Topological Measures" (meshlabserver
# under Xvfb, as export_meshlab.sh) must report no boundary edge and a two-manifold mesh (no non-manifold edge or
# vertex) for the level surfaces of every course mesh, the 69k open bunny, a soup of 100 random triangles, two boxes
# one ulp apart, a slab thinner than a cell, a mesh with its faces flipped at random, a 1x1x1 grid, bounds cutting
# the surface and levels != 0; assimp must import every format with the surface's triangle count. Also the tool's
# refusals: a grid without distances (exit 2, one line naming --sdf), a level beyond the band (exit 2), --surface
# with a voxel format (exit 1). Skips the MeshLab part when meshlabserver or xvfb-run is missing, the assimp part
# when assimp is.
# Usage: export_surface.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
[ -x "$build/vox-export" ] || { echo "SKIP: vox-export not built"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
seed=${VOX_SEED_DIR:-$src/data}

# Scenes made here: a soup, two boxes one ulp apart, a slab of a tenth of a cell, a bunny with faces flipped.
python3 - "$tmp" "$seed/6837/scenes/bunny_1k.obj" <<'PY'
import random, struct, sys
tmp, bunny = sys.argv[1], sys.argv[2]
random.seed(47)
with open(f"{tmp}/soup.obj", "w") as f:
    for _ in range(100):
        for _ in range(3):
            f.write("v %r %r %r\n" % tuple(random.uniform(-1, 1) for _ in range(3)))
    for i in range(100):
        f.write("f %d %d %d\n" % (3 * i + 1, 3 * i + 2, 3 * i + 3))
def box(f, lo, hi, base):
    for c in range(8):
        f.write("v %r %r %r\n" % tuple(hi[a] if c >> a & 1 else lo[a] for a in range(3)))
    for t in [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
              [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]:
        f.write("f %d %d %d\n" % tuple(base + v + 1 for v in t))
ulp = struct.unpack("<d", struct.pack("<q", struct.unpack("<q", struct.pack("<d", 1.0))[0] + 1))[0]
with open(f"{tmp}/ulp_boxes.obj", "w") as f:
    box(f, (0, 0, 0), (1, 1, 1), 0)
    box(f, (ulp, 0, 0), (2, 1, 1), 8)
with open(f"{tmp}/slab.obj", "w") as f:
    box(f, (0, 0, 0), (1, 1, 0.005), 0)
with open(bunny) as src, open(f"{tmp}/flipped.obj", "w") as f:
    for line in src:
        w = line.split()
        if w and w[0] == "f" and random.random() < 0.5:
            line = " ".join([w[0], w[1], w[3], w[2]]) + "\n"
        f.write(line)
PY

# "NAME SCENE LEVEL VOXELIZE-ARGS..." lines; each surface written as PLY for MeshLab.
cases=$tmp/cases.txt
{
  for obj in "$seed"/6837/scenes/*.obj; do echo "$(basename "$obj" .obj) $obj 0 --res 48 --sdf"; done
  echo "bun_zipper $seed/meshes/bun_zipper.ply 0 --res 96 --sdf"
  echo "bun_zipper_grown $seed/meshes/bun_zipper.ply 0.002 --res 96 --sdf 5"
  echo "soup $tmp/soup.obj 0 --res 64 --sdf"
  echo "ulp_boxes $tmp/ulp_boxes.obj 0 --res 32 --sdf"
  echo "slab $tmp/slab.obj 0.04 --grid 20 20 6 --bounds -0.25 -0.25 -0.225 1.25 1.25 0.225 --sdf"
  echo "flipped $tmp/flipped.obj 0 --res 48 --sdf"
  echo "one_cell $tmp/ulp_boxes.obj 0 --grid 1 1 1 --bounds 0.4 0.4 0.4 0.6 0.6 0.6 --sdf 64"
  echo "cut $seed/6837/scenes/bunny_5k.obj 0 --grid 30 20 30 --bounds -0.1 0.03 -0.06 0.06 0.12 0.06 --sdf"
  echo "shrunk $seed/6837/scenes/bunny_5k.obj -0.001 --res 64 --sdf 4"
} >"$cases"
list=$tmp/meshes.txt
: >"$list"
while read -r name scene level args; do
  # shellcheck disable=SC2086
  "$build/vox-voxelize" "$scene" -o "$tmp/$name.vgrid" $args --quiet 2>"$tmp/err" ||
    { fail "voxelize $name: $(cat "$tmp/err")"; continue; }
  "$build/vox-export" "$tmp/$name.vgrid" -o "$tmp/$name.ply" --surface "$level" --quiet 2>"$tmp/err" ||
    { fail "surface $name: $(cat "$tmp/err")"; continue; }
  echo "$name $tmp/$name.ply" >>"$list"
done <"$cases"

# Refusals: one line each, the exit codes of STYLE.md.
"$build/vox-voxelize" "$seed/6837/scenes/cube.obj" -o "$tmp/plain.vgrid" --res 8 --quiet
"$build/vox-export" "$tmp/plain.vgrid" -o "$tmp/x.ply" --surface 2>"$tmp/err"
rc=$?
{ [ "$rc" = 2 ] && [ "$(wc -l <"$tmp/err")" = 1 ] && grep -q -- "--sdf" "$tmp/err"; } ||
  fail "no distances: exit $rc, $(cat "$tmp/err")"
"$build/vox-export" "$tmp/cube.vgrid" -o "$tmp/x.ply" --surface 1 2>"$tmp/err"
rc=$?
{ [ "$rc" = 2 ] && grep -q "outside \[" "$tmp/err"; } || fail "level beyond the band: exit $rc, $(cat "$tmp/err")"
"$build/vox-export" "$tmp/cube.vgrid" -o "$tmp/x.binvox" --surface 2>"$tmp/err"
rc=$?
[ "$rc" = 1 ] || fail "--surface with .binvox: exit $rc, $(cat "$tmp/err")"
[ -e "$tmp/x.ply" ] && fail "a refused surface left a file"

# assimp: every mesh format of one surface, with its triangle count.
if command -v assimp >/dev/null; then
  "$build/vox-export" "$tmp/bunny_1k.vgrid" -o "$tmp/a.stl" --surface --quiet
  triangles=$((($(stat -c %s "$tmp/a.stl") - 84) / 50))
  for ext in ply obj off stl glb gltf; do
    "$build/vox-export" "$tmp/bunny_1k.vgrid" -o "$tmp/a.$ext" --surface --quiet || { fail "export $ext"; continue; }
    (cd "$tmp" && timeout 60 assimp info "$tmp/a.$ext") >"$tmp/info.log" 2>&1
    got=$(sed -n 's/^Faces: *//p' "$tmp/info.log")
    { grep -q "Importing file .*OK" "$tmp/info.log" && [ "$got" = "$triangles" ]; } ||
      fail "assimp $ext: faces $got, expected $triangles"
  done
  echo "export_surface: assimp imports ply obj off stl glb gltf ($triangles triangles)"
else
  echo "note: assimp not installed, not checked"
fi

if ! command -v meshlabserver >/dev/null || ! command -v xvfb-run >/dev/null; then
  echo "note: meshlabserver or xvfb-run not installed, MeshLab not checked"
else
  source "$src/tests/cli/lib/meshlab_topology.sh"
  meshlab_topology "$tmp" "$list"
  echo "export_surface: MeshLab checked $meshlab_checked surfaces"
fi
if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_surface: closed two-manifold surfaces, refusals as documented"
