#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (ASan + UBSan) and runs each for SECONDS seconds on a scratch copy
# of the seed corpus (scenes/, tests/data/, the course's seed scenes when present, and small files made here), two
# targets at a time on a 2-core machine. Nothing is written into the repository outside BUILD_DIR.
# Exits 1 naming each crashing (or leaking, hanging, out-of-memory) input when a target finds one.
# Usage: scripts/fuzz.sh BUILD_DIR SECONDS (FUZZ_TARGETS="grid voxel_writers" to run only those, as issue 23's
# 30-minute runs by hand did; FUZZ_TOOLS=DIR makes the seed grids and meshes with the vox-voxelize and vox-export of
# DIR, a build already made, instead of building instrumented ones here: CI passes its release build)
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: scripts/fuzz.sh BUILD_DIR SECONDS" >&2; exit 1; }
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$1"
build=$(cd "$1" && pwd)
seconds=$2
read -r -a targets <<<"${FUZZ_TARGETS:-course obj ply gltf glb grid voxel_writers}"

# -O1 -gline-tables-only, as OSS-Fuzz builds: about half the compile time of -O2 -g, and reports keep file:line.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVOX_FUZZ=ON \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -gline-tables-only -DNDEBUG" -DVOX_TESTS=OFF >/dev/null
if [ -n "${FUZZ_TOOLS:-}" ]; then
  tools=$(cd "$FUZZ_TOOLS" && pwd)
  ninja -C "$build" -j"$(nproc)" "${targets[@]/#/fuzz_}"
else
  tools=$build
  ninja -C "$build" -j"$(nproc)" "${targets[@]/#/fuzz_}" vox-voxelize vox-export
fi

run=$build/fuzz-run
rm -rf "$run"
mkdir -p "$run/tmp" "$run/made"
for t in course obj ply gltf glb grid voxel_writers; do mkdir -p "$run/$t/corpus" "$run/$t/artifacts"; done
export TMPDIR=$run/tmp  # the targets' private input folders (fuzz/fuzz_entry.h)
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# Seeds: copies only, each at most the target's -max_len (libFuzzer would cut longer ones).
declare -A max_len=([course]=8192 [obj]=8192 [ply]=8192 [gltf]=16384 [glb]=16384 [grid]=16384 [voxel_writers]=16384)
seed() {  # seed TARGET FILE...
  local t=$1 f; shift
  for f in "$@"; do
    [ -f "$f" ] && [ "$(stat -c %s "$f")" -le "${max_len[$t]}" ] && cp "$f" "$run/$t/corpus/$(basename "$f")"
  done
  return 0
}
shopt -s nullglob
seed_dir=$("$root/scripts/seed-dir.sh")
course_seeds=("$root"/scenes/*.txt "$seed_dir"/6837/scenes/*.txt)
seed course "${course_seeds[@]}"
seed obj "$root"/scenes/*.obj "$root"/tests/data/*.obj "$seed_dir"/6837/scenes/*.obj

# Small made files: a course scene with every primitive kind, an OBJ with polygons, negative indices and a .mtl
# reference, ASCII PLYs with float and double properties, a glTF with its buffer in a data URI; then grids of them
# and voxel meshes exported from those grids (binary PLY, OBJ, glTF, GLB).
m=$run/made
cat >"$m/all.txt" <<'EOF'
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Lights { numLights 2 DirectionalLight { direction -1 -1 -1 color 1 1 1 }
  PointLight { position 0 5 5 color 1 1 1 attenuation 1 0 0.1 } }
Background { color 0.1 0.1 0.1 ambientLight 0.2 0.2 0.2 }
Materials { numMaterials 2 Material { diffuseColor 1 0 0 }
  PhongMaterial { diffuseColor 0 1 0 specularColor 1 1 1 exponent 20 reflectiveColor 0.5 0.5 0.5
    transparentColor 0 0 0 indexOfRefraction 1.5 } }
Group { numObjects 4
  MaterialIndex 0
  Sphere { center 0 0 0 radius 1 }
  MaterialIndex 1
  Transform { Translate 2 0 0 Scale 1 0.5 1 YRotate 30 Rotate { 1 1 0 45 } Sphere { center 0 0 0 radius 0.5 } }
  Triangle { vertex0 -2 -2 0 vertex1 2 -2 0 vertex2 0 2 1e-3 }
  Plane { normal 0 1 0 offset -3 }
}
EOF
cat >"$m/poly.obj" <<'EOF'
mtllib none.mtl
o thing
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0.5 0.5 1.0000000000000002
vt 0 0
vn 0 0 1
g top
usemtl red
f 1/1/1 2/1/1 3/1/1 4/1/1
f -1 -2 -3
f 1//1 5//1 \
  2//1
EOF
cat >"$m/float.ply" <<'EOF'
ply
format ascii 1.0
comment made by scripts/fuzz.sh
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 1e-7
3 0 1 2
3 0 2 3
EOF
cat >"$m/double.ply" <<'EOF'
ply
format ascii 1.0
element vertex 3
property double x
property double y
property double z
property uchar red
property uchar green
property uchar blue
element face 1
property list uchar uint vertex_indices
end_header
10000000.000000002 0 0 255 0 0
0 0.1 0 0 255 0
0 0 1e-300 0 0 255
3 0 1 2
EOF
python3 - "$root/scenes/box/Box.gltf" "$root/scenes/box/Box0.bin" "$m/box_embedded.gltf" <<'EOF'
import base64, json, sys
gltf = json.load(open(sys.argv[1]))
data = base64.b64encode(open(sys.argv[2], "rb").read()).decode()
gltf["buffers"][0]["uri"] = "data:application/octet-stream;base64," + data
json.dump(gltf, open(sys.argv[3], "w"))
EOF
made_grid() {  # made_grid SCENE NAME [voxelize options]; a seed less if the scene is refused
  local scene=$1 name=$2; shift 2
  "$tools/vox-voxelize" "$scene" -o "$m/$name.vgrid" --quiet "$@" || echo "fuzz.sh: no seed $name.vgrid" >&2
}
made_grid "$m/all.txt" all --res 6
made_grid "$root/tests/data/unit_cube.obj" cube --grid 3 2 1 --method sat
made_grid "$root/scenes/scene5_02_spheres.txt" spheres --res 5 --method bbox
made_grid "$m/all.txt" fill --res 4 --fill
# Grid sets for the grid target, each as one input (fuzz/fuzz_entry.h, kSetPartMarker): the manifest, the scene file
# and the brick files in the manifest's order (ascending z, y, x), joined by a marker line.
made_set() {  # made_set SCENE NAME [voxelize options]; a seed less if the scene is refused
  local scene=$1 name=$2; shift 2
  mkdir -p "$m/sets"
  "$tools/vox-voxelize" "$scene" -o "$m/sets/$name.vgrid" --quiet "$@" || { echo "fuzz.sh: no seed $name set" >&2; return 0; }
  python3 - "$m/sets/$name.vgrid" "$m/${name}_set.vgrid" <<'PY'
import glob, re, sys
manifest, out = sys.argv[1], sys.argv[2]
# The set's files are in its generation folder NAME.bricks/gHEX/ (the only one: each seed set is written once).
folder = glob.glob(manifest[:-len('.vgrid')] + '.bricks/g*')[0]
def order(path):
    x, y, z = map(int, re.search(r'b_(\d+)_(\d+)_(\d+)\.vgrid$', path).groups())
    return (z, y, x)
bricks = sorted(glob.glob(folder + '/b_*.vgrid'), key=order)
parts = [open(p, 'rb').read() for p in [manifest, folder + '/scene.vgrid'] + bricks]
open(out, 'wb').write(b'\nVOXPART\n'.join(parts))
PY
}
made_set "$m/all.txt" all --res 6 --bricks 2 2 1
made_set "$root/tests/data/unit_cube.obj" cube --grid 3 2 1 --method sat --bricks 3 2 1
made_set "$m/all.txt" fill --res 4 --fill --bricks 2 1 2
for g in all cube spheres; do
  [ -f "$m/$g.vgrid" ] || continue
  for ext in ply obj gltf glb; do "$tools/vox-export" "$m/$g.vgrid" -o "$m/${g}_voxels.$ext" --faces merged --quiet; done
  "$tools/vox-export" "$m/$g.vgrid" -o "$m/${g}_ascii.ply" --ascii --faces exposed --quiet
done
seed course "$m"/*.txt
seed obj "$m"/*.obj
seed ply "$m"/*.ply
seed gltf "$m"/*.gltf
seed glb "$m"/*.glb
seed grid "$m"/*.vgrid
# The voxel writers: the crafted grids of issue 23 and small ones (grid files and compact descriptions,
# fuzz/voxel_writers_entry.h), and the grid files made above.
seed voxel_writers "$root"/tests/data/fuzz/voxel_writers/* "$m"/all.vgrid "$m"/cube.vgrid "$m"/spheres.vgrid "$m"/fill.vgrid

# As many targets at a time as there are cores; each writes its log, its exit code, and its findings as crash-*,
# leak-*, timeout-* or oom-* files.
fuzz_one() {
  local t=$1 code=0
  # The voxel writers' target runs every writer on each input (8 runs a second under the sanitizers): a mutated
  # input once took 21 s there (OpenVDB's tree and the meshes of a grid inside the harness's budget), which is slow,
  # not hung; its limit is wider so that CI's short run does not fail on such a unit (issue 23's note).
  local limits="-timeout=10"
  [ "$t" = voxel_writers ] && limits="-timeout=60 -report_slow_units=120"
  # shellcheck disable=SC2086
  "$build/fuzz/fuzz_$t" "$run/$t/corpus" -max_total_time="$seconds" $limits -rss_limit_mb=2048 \
    -max_len="${max_len[$t]}" -artifact_prefix="$run/$t/artifacts/" -print_final_stats=1 >"$run/$t.log" 2>&1 || code=$?
  echo "$code" >"$run/$t.code"
}
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$(nproc)" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
wait
status=0
for t in "${targets[@]}"; do
  code=$(cat "$run/$t.code")
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$run/$t.log")
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$run/$t.log")
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$run/$t.log" | tail -1 || true)
  echo "fuzz_$t: exit $code, ${execs:-?} runs, ${speed:-?} execs/s, ${cov:-no coverage line}," \
    "corpus $(ls "$run/$t/corpus" | wc -l) inputs"
  found=$(ls "$run/$t/artifacts")
  if [ "$code" -ne 0 ] || [ -n "$found" ]; then
    status=1
    for f in $found; do echo "fuzz_$t: FOUND $run/$t/artifacts/$f"; done
    grep -m1 -E 'ERROR: |runtime error|deadly signal|timeout|out-of-memory' "$run/$t.log" | sed "s/^/fuzz_$t: /" || true
    echo "fuzz_$t: log $run/$t.log"
  fi
done
exit $status
