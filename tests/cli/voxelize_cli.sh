#!/usr/bin/env bash
# vox-voxelize and vox-info as a user runs them: outputs, exit codes, one-line errors, nothing half-written.
# Usage: voxelize_cli.sh BUILD_DIR SOURCE_DIR
set -u
BIN=$1
SRC=$2
SEED=${VOX_SEED_DIR:-$SRC/data}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
# shellcheck source=lib/check.sh
source "$(dirname "$0")/lib/check.sh"

V=$BIN/vox-voxelize
I=$BIN/vox-info

check help 0 "$V" --help
grep -q -- "--method" "$T/out" || { echo "FAIL help lacks --method"; fails=$((fails + 1)); }
check version 0 "$V" --version
check sphere 0 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/s.vgrid" --grid 15 15 15 --quiet
check info 0 "$I" "$T/s.vgrid"
grep -q "occupied_cells:" "$T/out" || { echo "FAIL info output"; fails=$((fails + 1)); }
# A course camera spans the image's longer side (how vox-trace frames a non-square image); a mesh has no camera.
grep -q "^camera: orthographic (spans the longer side)$" "$T/out" || { echo "FAIL info camera span"; fails=$((fails + 1)); }
check info_json 0 "$I" "$T/s.vgrid" --json --cells --primitives
python3 - "$T/out" <<'PY' || fails=$((fails + 1))
import json, sys
d = json.load(open(sys.argv[1]))
assert d["dims"] == [15, 15, 15], d["dims"]
assert d["method"] == "exact"
assert d["primitive_counts"]["sphere"] == 1
assert d["occupied_cells"] == len(d["cells"]) > 0
assert d["references"] == sum(len(c["prims"]) for c in d["cells"])
s = d["primitives"][0]
assert s["type"] == "sphere" and s["radius"] > 0
# Recheck every cell from the JSON alone: the sphere surface meets the closed cell (rationals, exact).
from fractions import Fraction as F
lo = [F(x) for x in d["bounds"]["min"]]; hi = [F(x) for x in d["bounds"]["max"]]
c = [F(x) for x in s["center"]]; r2 = F(s["radius"]) ** 2
def b(a, i):  # the one boundary formula, in double as the contract says
    n = d["dims"][a]
    return F(float(d["bounds"]["min"][a]) + (float(d["bounds"]["max"][a]) - float(d["bounds"]["min"][a])) * i / n)
cells = {tuple(x["ijk"]) for x in d["cells"]}
for i in range(15):
    for j in range(15):
        for k in range(15):
            l = [b(0, i), b(1, j), b(2, k)]; h = [b(0, i + 1), b(1, j + 1), b(2, k + 1)]
            near = sum((min(max(c[a], l[a]), h[a]) - c[a]) ** 2 for a in range(3))
            far = sum(max((l[a] - c[a]) ** 2, (h[a] - c[a]) ** 2) for a in range(3))
            assert ((near <= r2 <= far) == ((i, j, k) in cells)), (i, j, k)
PY
check res 0 "$V" "$SRC/scenes/scene5_12_nested_transformations.txt" -o "$T/n.vgrid" --res 20 --method sat --stats
grep -q "^occupied_cells: " "$T/err" || { echo "FAIL --stats"; fails=$((fails + 1)); }
# The phases of the whole process, each timed (issue 26): read, voxelize, write, sync.
for f in read_seconds voxelize_seconds write_seconds sync_seconds total_seconds; do
  grep -q "^$f: [0-9]" "$T/err" || { echo "FAIL --stats lacks $f"; fails=$((fails + 1)); }
done

# Bad input: one line naming the file, exit codes 1 usage, 2 bad input, 3 cannot write.
check missing_scene 2 "$V" "$T/none.txt" -o "$T/x.vgrid"; expect_err missing_scene "none.txt"
printf 'Group {\n numObjects 1\n Sphere { center 0 nan 0 radius 1 }\n}\n' >"$T/nan.txt"
check nan 2 "$V" "$T/nan.txt" -o "$T/x.vgrid"; expect_err nan "nan.txt"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' >"$T/bad.obj"
check face_index 2 "$V" "$T/bad.obj" -o "$T/x.vgrid"; expect_err face_index "bad.obj"
printf 'Group {\n numObjects 1\n TriangleMesh { obj_file missing.obj }\n}\n' >"$T/mesh.txt"
check missing_mesh 2 "$V" "$T/mesh.txt" -o "$T/x.vgrid"; expect_err missing_mesh "missing.obj"
check zero_grid 1 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/x.vgrid" --grid 0 4 4; expect_err zero_grid "dimension"
check negative_grid 1 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/x.vgrid" --grid -3 4 4; expect_err negative_grid "grid"
check absurd_grid 2 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/x.vgrid" --grid 100000 100000 100000; expect_err absurd_grid "MiB"
check bad_method 1 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/x.vgrid" --method magic; expect_err bad_method "method"
check unwritable 3 "$V" "$SRC/scenes/scene5_01_sphere.txt" -o "$T/no/such/dir/x.vgrid"; expect_err unwritable "x.vgrid"
[ ! -e "$T/x.vgrid" ] || { echo "FAIL a failed run left an output file"; fails=$((fails + 1)); }
ls -a "$T" | grep -q '\.tmp' && { echo "FAIL temporary file left behind"; fails=$((fails + 1)); }
head -c 100 "$T/s.vgrid" >"$T/trunc.vgrid"
check truncated 2 "$I" "$T/trunc.vgrid"; expect_err truncated "trunc.vgrid"
check not_a_grid 2 "$I" "$SRC/scenes/scene5_01_sphere.txt"; expect_err not_a_grid "magic"

echo "$passes passed, $fails failed"
[ "$fails" = 0 ]
