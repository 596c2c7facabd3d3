#!/usr/bin/env bash
# vox-trace end to end: a normal run with --stats, grid and brute force giving identical files, and bad input:
# exit codes of STYLE.md (1 usage, 2 bad input, 3 cannot write), a one-line error, no partial image left behind.
# Usage: trace_cli.sh BUILD_DIR SOURCE_DIR
set -u
BUILD=$1
SRC=$2
SEED="${VOX_SEED_DIR:-$SRC/data}/6837/scenes"
TRACE="$BUILD/vox-trace"
VOXELIZE="$BUILD/vox-voxelize"
WORK=$(mktemp -d)
trap 'chmod -R u+w "$WORK"; rm -rf "$WORK"' EXIT
failures=0

fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# expect CODE DESCRIPTION -- command...: exit code and a single line on stderr for errors.
expect() {
  local code=$1 what=$2
  shift 3
  "$@" >"$WORK/out.txt" 2>"$WORK/err.txt"
  local got=$?
  if [ "$got" != "$code" ]; then
    fail "$what: exit $got, expected $code"
    sed 's/^/    /' "$WORK/err.txt" | head -5
  elif [ "$code" != 0 ]; then
    # One error line; option-parsing errors may add the shared "Run with --help for usage." hint.
    local errors others
    errors=$(grep -c '^vox-trace: error: ' "$WORK/err.txt")
    others=$(grep -v -e '^vox-trace: error: ' -e '^Run with --help for usage.$' "$WORK/err.txt" | grep -c .)
    [ "$errors" = 1 ] && [ "$others" = 0 ] || fail "$what: expected one 'vox-trace: error:' line, got: $(head -3 "$WORK/err.txt")"
  fi
}

"$VOXELIZE" "$SEED/scene6_02_sphere_triangles.txt" -o "$WORK/s.vgrid" --grid 10 10 10 -q || { echo "FAIL: voxelize"; exit 1; }
"$VOXELIZE" "$SEED/scene5_07_bunny_mesh_1k.txt" -o "$WORK/b.vgrid" --grid 15 15 12 --method bbox -q || { echo "FAIL: voxelize"; exit 1; }

# A normal run: image written, stats on stderr, nothing on stdout.
expect 0 "normal run" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/ok.png" --size 64 48 --stats --quiet
[ -s "$WORK/ok.png" ] || fail "normal run: no image"
[ -s "$WORK/out.txt" ] && fail "normal run: stdout not empty"
for key in rays trace_seconds rays_per_second cells_per_ray tests_per_ray mailbox_skips_per_ray; do
  grep -Eq "^$key: [0-9.e+-]+$" "$WORK/err.txt" || fail "--stats: no '$key:' line"
done

# Grid and brute force give the same file, byte for byte, in every mode (shadows included in shade).
for mode in shade normals depth; do
  "$TRACE" "$WORK/b.vgrid" -o "$WORK/g_$mode.png" --size 40 40 --mode $mode --accel grid -q || fail "$mode grid"
  "$TRACE" "$WORK/b.vgrid" -o "$WORK/n_$mode.png" --size 40 40 --mode $mode --accel none -q || fail "$mode none"
  cmp -s "$WORK/g_$mode.png" "$WORK/n_$mode.png" || fail "$mode: grid and none images differ"
done
# The course's recursive lines (issue 12): the glass sphere with its flags, grid and brute force the same file.
"$VOXELIZE" "$SEED/scene6_14_glass_sphere.txt" -o "$WORK/g.vgrid" --grid 20 20 20 -q || fail "voxelize glass sphere"
for accel in grid none; do
  expect 0 "glass sphere $accel" -- "$TRACE" "$WORK/g.vgrid" -o "$WORK/glass_$accel.png" --size 32 32 --shade-back \
    --bounces 5 --weight 0.01 --samples 4 --filter gaussian 0.4 --accel $accel -q
done
cmp -s "$WORK/glass_grid.png" "$WORK/glass_none.png" || fail "glass sphere: grid and none images differ"
expect 0 "count mode prints its scale" -- "$TRACE" "$WORK/b.vgrid" -o "$WORK/c.png" --size 20 20 --mode count --stats -q
grep -Eq '^count_scale_max: [0-9.]+$' "$WORK/err.txt" || fail "count mode: no count_scale_max line"
expect 0 "depth to EXR" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/d.exr" --size 20 20 --mode depth -q
# Its channel list (OpenEXR header attribute "channels", type chlist): one float channel named Z, the name
# compositors take as depth (issue 10; OpenImageIO's default for one channel is Y).
channels=$(python3 - "$WORK/d.exr" <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
at = 8  # magic and version
while data[at] != 0:
    name_end = data.index(b"\0", at)
    type_end = data.index(b"\0", name_end + 1)
    size = struct.unpack_from("<i", data, type_end + 1)[0]
    value = data[type_end + 5:type_end + 5 + size]
    if data[at:name_end] == b"channels":
        out, k = [], 0
        while value[k] != 0:
            end = value.index(b"\0", k)
            pixel_type = struct.unpack_from("<i", value, end + 1)[0]
            out.append("%s:%s" % (value[k:end].decode(), {0: "uint", 1: "half", 2: "float"}[pixel_type]))
            k = end + 17
        print(" ".join(out))
    at = type_end + 5 + size
PY
)
[ "$channels" = "Z:float" ] || fail "depth EXR channels are '$channels', expected one float channel Z"
expect 0 "voxels, samples, camera overrides, threads" -- "$TRACE" "$WORK/b.vgrid" -o "$WORK/v.tga" --size 30 20 \
  --mode voxels --samples 4 --eye 0 0.3 1 --look-at 0 0.2 0 --up 0 1 0 --fov 40 --threads 1 -q

# Camera conventions (DESIGN.md "vox-trace"): the course's angle spans the longer side of the image, --fov and glTF's
# yfov the height. scene6_02's camera has angle 30: on a square image --fov 30 gives the same file, on a wide one
# --fov 30 frames less (the flag stays vertical and overrides); --eye/--look-at keep the scene's angle and its side.
frame() {  # NAME SIZE... -- extra options
  local name=$1 w=$2 h=$3
  shift 3
  "$TRACE" "$WORK/s.vgrid" -o "$WORK/cam_$name.png" --size "$w" "$h" --mode normals -q "$@" || fail "camera $name"
}
frame sq 24 24
frame sq_fov 24 24 --fov 30
cmp -s "$WORK/cam_sq.png" "$WORK/cam_sq_fov.png" || fail "course camera on a square image: --fov 30 changed it"
frame wide 48 24
frame wide_fov 48 24 --fov 30
cmp -s "$WORK/cam_wide.png" "$WORK/cam_wide_fov.png" && fail "course camera on a wide image: --fov 30 did not override"
frame eye 48 24 --eye 0 2 10 --look-at 0 1 5
frame eye_fov 48 24 --eye 0 2 10 --look-at 0 1 5 --fov 30
cmp -s "$WORK/cam_eye.png" "$WORK/cam_eye_fov.png" && fail "--eye: the course's angle did not keep its side"
frame eye_sq 24 24 --eye 0 2 10 --look-at 0 1 5
frame eye_sq_fov 24 24 --eye 0 2 10 --look-at 0 1 5 --fov 30
cmp -s "$WORK/cam_eye_sq.png" "$WORK/cam_eye_sq_fov.png" || fail "--eye on a square image: --fov 30 changed it"
# A glTF camera (yfov 0.7 radians) is vertical: a wide image with it and with --fov of the same angle is one file.
GLTF="${VOX_SEED_DIR:-$SRC/data}/gltf/Cameras/glTF/Cameras.gltf"
"$VOXELIZE" "$GLTF" -o "$WORK/gltf.vgrid" --grid 4 4 1 -q || fail "voxelize glTF camera scene"
yfov=$(python3 -c 'import math; print(repr(0.7 * 180 / math.pi))')
for fov in "" "--fov $yfov"; do
  # shellcheck disable=SC2086
  "$TRACE" "$WORK/gltf.vgrid" -o "$WORK/gltf${fov:+_fov}.png" --size 48 24 --mode normals -q $fov || fail "glTF $fov"
done
cmp -s "$WORK/gltf.png" "$WORK/gltf_fov.png" || fail "glTF camera on a wide image: not the vertical --fov $yfov"

# Bad grid files: truncated, corrupt, missing, not a grid at all.
size=$(stat -c %s "$WORK/s.vgrid")
head -c $((size / 2)) "$WORK/s.vgrid" >"$WORK/truncated.vgrid"
cp "$WORK/s.vgrid" "$WORK/corrupt.vgrid"
printf '\xff\xff\xff\xff\xff\xff\xff\xff' | dd of="$WORK/corrupt.vgrid" bs=1 seek=$((size / 2)) conv=notrunc status=none
mkdir "$WORK/outs"
expect 2 "truncated grid" -- "$TRACE" "$WORK/truncated.vgrid" -o "$WORK/outs/a.png" -q
expect 2 "corrupt grid" -- "$TRACE" "$WORK/corrupt.vgrid" -o "$WORK/outs/a.png" -q
expect 2 "missing grid" -- "$TRACE" "$WORK/nothere.vgrid" -o "$WORK/outs/a.png" -q
expect 2 "scene file given as grid" -- "$TRACE" "$SEED/scene6_02_sphere_triangles.txt" -o "$WORK/outs/a.png" -q

# Bad options.
expect 1 "size 0" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --size 0 10 -q
expect 1 "size 100000x100000" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --size 100000 100000 -q
expect 1 "size over 2^28 pixels" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --size 16384 16385 -q
expect 1 "negative size" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --size -5 10 -q
expect 1 "unknown mode" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --mode fancy -q
expect 1 "unknown accel" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --accel bvh -q
expect 1 "samples 0" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --samples 0 -q
expect 1 "fov 180" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --fov 180 -q
expect 1 "eye without look-at" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --eye 0 0 1 -q
expect 1 "NaN eye" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --eye nan 0 1 --look-at 0 0 0 -q
grep -q "must be finite" "$WORK/err.txt" || fail "NaN eye: message does not say the eye must be finite"
expect 1 "unknown image format" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.xyz" -q
expect 1 "negative weight" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --weight -1 -q
expect 1 "NaN weight" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --weight nan -q
expect 1 "bounces 11" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --bounces 11 -q
expect 1 "unknown filter" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --filter sinc 1 -q
expect 1 "filter radius 0" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --filter box 0 -q
expect 1 "filter radius not a number" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --filter tent x -q
expect 1 "filter without radius" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/a.png" --filter gaussian -q
expect 1 "no output" -- "$TRACE" "$WORK/s.vgrid" -q

# Unwritable outputs: missing folder, a file used as a folder, a folder as the output, a read-only folder.
expect 3 "missing folder" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/missing/a.png" --size 8 8 -q
touch "$WORK/outs/plainfile"
expect 3 "file as folder" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/plainfile/a.png" --size 8 8 -q
mkdir "$WORK/outs/dir.png"
expect 3 "folder as output" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/outs/dir.png" --size 8 8 -q
if [ "$(id -u)" != 0 ]; then  # root writes into read-only folders anyway
  mkdir "$WORK/ro" && chmod a-w "$WORK/ro"
  expect 3 "read-only folder" -- "$TRACE" "$WORK/s.vgrid" -o "$WORK/ro/a.png" --size 8 8 -q
  [ -z "$(ls -A "$WORK/ro")" ] || fail "read-only folder: files left behind"
fi

# No partial image or temporary file left behind by any failure above.
left=$(cd "$WORK/outs" && ls -A | grep -v -x -e plainfile -e dir.png)
[ -z "$left" ] || fail "files left behind: $left"

if [ $failures -ne 0 ]; then
  echo "$failures failure(s)"
  exit 1
fi
echo "trace_cli: all checks passed"
