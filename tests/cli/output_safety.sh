#!/usr/bin/env bash
# Outputs that cannot be written must never cost the user a file (issue 9, "Outputs"):
#  - a full disk (a small tmpfs when root can mount one, and RLIMIT_FSIZE, which makes write() fail with EFBIG) gives
#    exit 3 for every output kind, with the old output byte-identical and no temporary file left;
#  - device outputs are written into, never replaced: /dev/full exit 3, /dev/null exit 0 and still a device, a FIFO
#    with a reader gets the bytes and stays a FIFO, a FIFO without one is refused at once, other nodes are refused;
#  - SIGINT/SIGTERM during a large write end with 130/143 (or 0 when the write had finished) and no temporary file;
#  - an output that is the input (also through a symlink or a hard link) is refused with exit 1, the input untouched.
# Usage: output_safety.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
V=$build/vox-voxelize
E=$build/vox-export
T=$build/vox-trace
for t in "$V" "$E" "$T"; do [ -x "$t" ] || { echo "missing $t"; exit 1; }; done
tmp=$(mktemp -d)
full=$tmp/full  # the tmpfs mount point, when there is one
mounted=0
cleanup() {
  [ "$mounted" = 1 ] && umount "$full" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
skip() { echo "SKIP: $*"; }

# Exit code of a command, its stderr in $tmp/err.
run() { "$@" >/dev/null 2>"$tmp/err"; echo $?; }
expect_code() {  # expect_code CODE DESCRIPTION COMMAND...
  local want=$1 what=$2; shift 2
  local got; got=$(run "$@")
  [ "$got" = "$want" ] || fail "$what: exit $got, expected $want ($(head -c 300 "$tmp/err"))"
}
expect_clean() {  # expect_clean DIR DESCRIPTION: no hidden temporary file left in DIR
  local left; left=$(find "$1" -maxdepth 1 -name '.*tmp*' | head -1)
  [ -z "$left" ] || fail "$2: left behind: $left"
}

# Inputs: a small grid (small outputs, the "old" files) and a larger one whose outputs fill a 32 KB disk.
expect_code 0 "voxelize small" "$V" "$src/scenes/scene5_01_sphere.txt" -o "$tmp/small.vgrid" --grid 3 3 3 -q
expect_code 0 "voxelize large" "$V" "$src/scenes/teapot.obj" -o "$tmp/large.vgrid" --res 48 -q
[ -s "$tmp/small.vgrid" ] && [ -s "$tmp/large.vgrid" ] || { echo "FAIL: cannot make the input grids"; exit 1; }

# The output kinds: NAME|COMMAND-FOR-THE-SMALL-OUTPUT|COMMAND-FOR-THE-LARGE-OUTPUT, OUT standing for the output path.
kinds=(
  "grid.vgrid|$V $src/scenes/scene5_01_sphere.txt -o OUT --grid 3 3 3 -q|$V $src/scenes/teapot.obj -o OUT --res 96"
)
for ext in ply obj off stl glb gltf; do
  kinds+=("mesh.$ext|$E $tmp/small.vgrid -o OUT -q|$E $tmp/large.vgrid -o OUT --faces all -q")
done
kinds+=("ascii.ply|$E $tmp/small.vgrid -o OUT --ascii -q|$E $tmp/large.vgrid -o OUT --ascii --faces all -q")
for ext in png tga bmp jpg exr; do
  mode=normals
  [ "$ext" = png ] && mode=count  # compresses less
  small="$T $tmp/small.vgrid -o OUT --size 4 4 -q"
  kinds+=("image.$ext|$small|$T $tmp/large.vgrid -o OUT --size 1024 1024 --mode $mode -q")
done

# full_disk_case LABEL DIR NAME SMALL LARGE [WRAPPER...]: the old output made by SMALL in DIR, then LARGE must fail
# with exit 3 under WRAPPER (nothing: the disk itself is full), leaving the old output as it was and no temporary.
full_disk_case() {
  local label=$1 dir=$2 name=$3 small=$4 large=$5; shift 5
  local out=$dir/$name
  rm -f "$dir"/* "$dir"/.*tmp* 2>/dev/null
  expect_code 0 "$label $name: old output" ${small//OUT/$out}
  [ -s "$out" ] || { fail "$label $name: old output missing"; return; }
  cp "$out" "$tmp/reference"
  expect_code 3 "$label $name" "$@" ${large//OUT/$out}
  grep -q "cannot write" "$tmp/err" || fail "$label $name: message lacks 'cannot write': $(head -c 200 "$tmp/err")"
  cmp -s "$out" "$tmp/reference" || fail "$label $name: old output changed"
  expect_clean "$dir" "$label $name"
}

# RLIMIT_FSIZE of 8 KB: write() fails with EFBIG (SIGXFSZ ignored, as the test wants the error, not the signal).
limited() { (trap '' XFSZ; ulimit -f 8; exec "$@"); }
mkdir "$tmp/lim"
for kind in "${kinds[@]}"; do
  IFS='|' read -r name small large <<<"$kind"
  full_disk_case "ulimit -f" "$tmp/lim" "$name" "$small" "$large" limited
done

# A real full disk: a 32 KB tmpfs (the large outputs all exceed it).
mkdir "$full"
if [ "$(id -u)" = 0 ] && mount -t tmpfs -o size=32k tmpfs "$full" 2>/dev/null; then
  mounted=1
  for kind in "${kinds[@]}"; do
    IFS='|' read -r name small large <<<"$kind"
    full_disk_case "full tmpfs" "$full" "$name" "$small" "$large"
  done
  umount "$full" && mounted=0
else
  skip "full tmpfs: not root or mount refused (the ulimit -f checks above stand in)"
fi

# Devices: written into, never replaced by a regular file. As root a broken tool would replace the machine's own
# /dev/null and /dev/full, so private nodes are tried first, the real ones only when those survive, and any real
# node found replaced is put back.
sphere="$src/scenes/scene5_01_sphere.txt"
restore_node() {  # restore_node PATH MAJOR MINOR
  [ -c "$1" ] && return 0
  fail "$1 is no longer a character device (restored)"
  mknod -m 666 "$1.vox-restore" c "$2" "$3" && mv -f "$1.vox-restore" "$1"
}
if [ "$(id -u)" != 0 ]; then
  # Not root: the folder /dev is not writable, so nothing can be replaced there.
  expect_code 3 "voxelize -o /dev/full" "$V" "$sphere" -o /dev/full --grid 3 3 3 -q
  grep -q "No space left on device" "$tmp/err" || fail "/dev/full: message lacks the reason: $(head -c 99 "$tmp/err")"
  skip "/dev/null as output and device nodes of our own: need root (the FIFO checks below stand in)"
elif mknod "$tmp/null.vgrid" c 1 3 && mknod "$tmp/full.vgrid" c 1 7 && mknod "$tmp/null.ply" c 1 3 &&
  mknod "$tmp/full.png" c 1 7 && mknod "$tmp/blk.ply" b 7 0; then
  before=$failures
  expect_code 0 "voxelize into a null device" "$V" "$sphere" -o "$tmp/null.vgrid" --grid 3 3 3 -q
  expect_code 3 "voxelize into a full device" "$V" "$sphere" -o "$tmp/full.vgrid" --grid 3 3 3 -q
  grep -q "No space left on device" "$tmp/err" || fail "full device: message lacks the reason: $(head -c 99 "$tmp/err")"
  # Export and trace take the format from the extension: nodes with one.
  expect_code 0 "export into a null device" "$E" "$tmp/small.vgrid" -o "$tmp/null.ply" -q
  expect_code 3 "trace into a full device" "$T" "$tmp/small.vgrid" -o "$tmp/full.png" --size 64 64 -q
  expect_code 3 "export into a block device" "$E" "$tmp/small.vgrid" -o "$tmp/blk.ply" -q
  for node in null.vgrid full.vgrid null.ply full.png; do [ -c "$tmp/$node" ] || fail "$node: not a device"; done
  [ -b "$tmp/blk.ply" ] || fail "blk.ply is no longer a block device"
  rm -f "$tmp/null.vgrid" "$tmp/full.vgrid" "$tmp/null.ply" "$tmp/full.png" "$tmp/blk.ply"
  if [ "$failures" = "$before" ]; then
    expect_code 3 "voxelize -o /dev/full" "$V" "$sphere" -o /dev/full --grid 3 3 3 -q
    restore_node /dev/full 1 7
    expect_code 0 "voxelize -o /dev/null" "$V" "$sphere" -o /dev/null --grid 3 3 3 -q
    restore_node /dev/null 1 3
  else
    fail "/dev/null and /dev/full not tried: the tools replaced device nodes of their own"
  fi
else
  skip "mknod refused: /dev/null, /dev/full and other device nodes as outputs not checked"
fi

# FIFOs: written into when read, refused at once when nobody reads.
mkfifo "$tmp/pipe.ply" "$tmp/pipe.png" "$tmp/pipe.vgrid"
for case in "pipe.vgrid|$V $src/scenes/scene5_01_sphere.txt -o OUT --grid 3 3 3 -q" \
            "pipe.ply|$E $tmp/small.vgrid -o OUT -q" "pipe.png|$T $tmp/small.vgrid -o OUT --size 16 16 -q"; do
  IFS='|' read -r name cmd <<<"$case"
  fifo=$tmp/$name
  expect_code 3 "$name without reader" timeout 20 ${cmd//OUT/$fifo}
  grep -q "no reader" "$tmp/err" || fail "$name without reader: message: $(head -c 200 "$tmp/err")"
  wc -c <"$fifo" >"$tmp/count" &
  reader=$!
  expect_code 0 "$name with reader" timeout 20 ${cmd//OUT/$fifo}
  wait "$reader"
  [ "$(cat "$tmp/count")" -gt 0 ] || fail "$name: the reader got no bytes"
  [ -p "$fifo" ] || fail "$name is no longer a FIFO"
done
expect_clean "$tmp" "FIFOs"

# Signals during a large write. Job control gives background jobs their own process group with SIGINT not ignored
# (a non-interactive shell starts them with SIGINT ignored, which the tools rightly keep).
set -m
expect_code 0 "voxelize huge" "$V" "$src/scenes/teapot.obj" -o "$tmp/huge.vgrid" --res 512 -q
mkdir "$tmp/sig"
interrupted=0
signal_case() {  # signal_case SIGNAL CODE DELAY|tmp COMMAND...: DELAY seconds, or "tmp": once the temporary exists
  local sig=$1 code=$2 when=$3; shift 3
  rm -f "$tmp/sig"/* "$tmp/sig"/.*tmp* 2>/dev/null
  "$@" >/dev/null 2>&1 &
  local pid=$! i
  if [ "$when" = tmp ]; then
    for ((i = 0; i < 2000; ++i)); do
      [ -n "$(find "$tmp/sig" -maxdepth 1 -name '.*tmp*' | head -1)" ] && break
      sleep 0.01
    done
  else
    sleep "$when"
  fi
  kill -s "$sig" "$pid" 2>/dev/null
  { wait "$pid"; } 2>/dev/null  # no "Interrupt" job notice in the log
  local got=$?
  if [ "$got" = "$code" ]; then
    interrupted=$((interrupted + 1))
    # The signal may land after the rename and before the exit: then the output is there and whole (a grid file
    # proves it by its checksum); a temporary file must never be left (expect_clean below).
    local left
    for left in "$tmp/sig"/*; do
      [ -e "$left" ] || continue
      case $left in
        *.vgrid) "$build/vox-info" "$left" >/dev/null 2>&1 || fail "SIG$sig at $when ($*): left a broken $left" ;;
      esac
    done
  elif [ "$got" != 0 ]; then
    fail "SIG$sig at $when ($*): exit $got, expected $code or 0"
  fi
  expect_clean "$tmp/sig" "SIG$sig at $when"
}
# Under the sanitizers (CI's second pass: same code, ten times slower) two moments suffice.
moments="tmp 0.1 0.5 1.2"
grep -qs '^VOX_SANITIZE:BOOL=ON' "$build/CMakeCache.txt" && moments="tmp 0.5"
for when in $moments; do
  signal_case INT 130 "$when" "$E" "$tmp/huge.vgrid" -o "$tmp/sig/m.obj" --faces all -q
  signal_case TERM 143 "$when" "$E" "$tmp/huge.vgrid" -o "$tmp/sig/m.ply" --faces all -q
done
signal_case INT 130 tmp "$T" "$tmp/huge.vgrid" -o "$tmp/sig/i.tga" --size 2048 2048 --mode normals -q
signal_case TERM 143 tmp "$V" "$src/scenes/teapot.obj" -o "$tmp/sig/g.vgrid" --res 512 -q
set +m
[ "$interrupted" -gt 0 ] || fail "no signal arrived before a write finished: the signal checks proved nothing"

# The output is the input: refused before anything is read, the input untouched.
cp "$src/scenes/cube.obj" "$tmp/scene.obj"
cp "$tmp/small.vgrid" "$tmp/grid.ply"
cp "$tmp/small.vgrid" "$tmp/grid.png"
cp "$tmp/small.vgrid" "$tmp/grid.mtl"
ln -s scene.obj "$tmp/scene_link.obj"
ln "$tmp/grid.ply" "$tmp/grid_hard.ply"
ln -s grid.png "$tmp/grid_link.png"
cp "$tmp/scene.obj" "$tmp/scene.ref"
cp "$tmp/small.vgrid" "$tmp/grid.ref"
for case in "voxelize|$V $tmp/scene.obj -o $tmp/scene.obj" \
            "voxelize via symlink|$V $tmp/scene.obj -o $tmp/scene_link.obj" \
            "export|$E $tmp/grid.ply -o $tmp/grid.ply" "export via hard link|$E $tmp/grid.ply -o $tmp/grid_hard.ply" \
            "export OBJ whose .mtl is the grid|$E $tmp/grid.mtl -o $tmp/grid.obj" \
            "trace|$T $tmp/grid.png -o $tmp/grid.png" "trace via symlink|$T $tmp/grid_link.png -o $tmp/grid.png"; do
  IFS='|' read -r what cmd <<<"$case"
  expect_code 1 "output is input: $what" $cmd
  grep -q "same file as the input" "$tmp/err" || fail "output is input: $what: message: $(head -c 200 "$tmp/err")"
done
cmp -s "$tmp/scene.obj" "$tmp/scene.ref" || fail "output is input: the scene changed"
cmp -s "$tmp/grid.ply" "$tmp/grid.ref" || fail "output is input: the grid (export) changed"
cmp -s "$tmp/grid.png" "$tmp/grid.ref" || fail "output is input: the grid (trace) changed"
cmp -s "$tmp/grid.mtl" "$tmp/grid.ref" || fail "output is input: the grid named .mtl changed"
[ -L "$tmp/scene_link.obj" ] && [ -L "$tmp/grid_link.png" ] || fail "output is input: a symlink was replaced"
expect_clean "$tmp" "output is input"

if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "output_safety: all checks passed ($interrupted writes interrupted by a signal)"
