#!/usr/bin/env bash
# A real client: MeshLab's meshlabserver, run headless under Xvfb, opens exported PLY files and its "Compute
# Topological Measures" filter must report no boundary edge and a two-manifold mesh, for the exposed and merged
# surfaces. Skips (exit 0) when meshlabserver or xvfb-run is missing; CI installs them
# (apt-get install --no-install-recommends meshlab xvfb xauth).
# Usage: export_meshlab.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
if ! command -v meshlabserver >/dev/null || ! command -v xvfb-run >/dev/null; then
  echo "SKIP: meshlabserver or xvfb-run not installed"
  exit 0
fi
[ -x "$build/vox-voxelize" ] || { echo "SKIP: vox-voxelize not built"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# A cube and a tilted triangle crossing near it: voxels meeting along edges and at corners.
{ cat "$src/tests/data/unit_cube.obj"; cat <<'OBJ'
v 1.3 -0.2 0.1
v 2.4 0.9 1.7
v 1.1 1.6 0.4
f 9 10 11
OBJ
} >"$tmp/scene.obj"
"$build/vox-voxelize" "$tmp/scene.obj" -o "$tmp/g.vgrid" --grid 14 10 10 --quiet || { echo "FAIL: voxelize"; exit 1; }
cat >"$tmp/topo.mlx" <<'MLX'
<!DOCTYPE FilterScript>
<FilterScript>
 <filter name="Compute Topological Measures"/>
</FilterScript>
MLX

for faces in exposed merged; do
  for extra in "" "--ascii"; do
    mesh="$tmp/$faces.ply"
    "$build/vox-export" "$tmp/g.vgrid" -o "$mesh" --faces "$faces" $extra --quiet || { fail "export $faces"; continue; }
    log="$tmp/$faces.log"
    (cd "$tmp" && timeout 120 xvfb-run -a meshlabserver -i "$mesh" -s "$tmp/topo.mlx") >"$log" 2>&1
    if ! grep -q "Boundary Edges" "$log"; then
      fail "$faces $extra: meshlabserver printed no topology ($(tail -3 "$log" | tr '\n' ' '))"
      continue
    fi
    grep -q "Boundary Edges 0" "$log" || fail "$faces $extra: $(grep 'Boundary Edges' "$log" | head -1)"
    grep -q "Mesh is two-manifold" "$log" || fail "$faces $extra: not two-manifold: $(grep -i manifold "$log" | head -2 | tr '\n' ' ')"
    echo "$faces $extra: $(grep -m1 'V: ' "$log" | sed 's/LOG: [0-9]* //'), $(grep -m1 -o 'Genus is [-0-9]*' "$log")"
  done
done
if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_meshlab: MeshLab reports closed two-manifold meshes"
