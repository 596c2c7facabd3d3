#!/usr/bin/env bash
# scripts/check-layers.sh must fail on a backwards include, or its passing run (ctest check_layers) proves nothing:
# on copies of libvox/ it passes untouched, then fails (exit 1, naming FILE:LINE and the include) on each planted
# include that runs against docs/architecture.md: upwards, sideways, into another stage's internals, a private header
# from a public one, the angle-bracket form, a stage folder not in the order, a file outside any stage.
# Usage: check_layers_plant.sh SOURCE_DIR
set -u
SRC=$1
CHECK=$SRC/scripts/check-layers.sh
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
fails=0
passes=0

fresh() {
  rm -rf "$T/tree"
  mkdir -p "$T/tree"
  cp -r "$SRC/libvox" "$T/tree/"
}

# plant NAME FILE TEXT [EXPECTED]: TEXT as line 2 of FILE (relative to the tree; line 1 of a file made new), then the
# check must exit 1 and print EXPECTED (default "FILE:2: TEXT").
plant() {
  local name=$1 file=$2 text=$3 expected=${4:-$2:2: $3}
  fresh
  local path=$T/tree/$file
  mkdir -p "$(dirname "$path")"
  touch "$path"
  { head -n 1 "$path"; printf '%s\n' "$text"; tail -n +2 "$path"; } >"$T/planted"
  mv "$T/planted" "$path"
  bash "$CHECK" "$T/tree" >"$T/out" 2>&1
  local code=$?
  if [ "$code" != 1 ]; then
    echo "FAIL $name: exit $code, expected 1"
    cat "$T/out"
    fails=$((fails + 1))
  elif ! grep -qF "$expected" "$T/out"; then
    echo "FAIL $name: the output does not say: $expected"
    cat "$T/out"
    fails=$((fails + 1))
  else
    passes=$((passes + 1))
  fi
}

fresh
if bash "$CHECK" "$T/tree" >"$T/out" 2>&1; then
  passes=$((passes + 1))
else
  echo "FAIL the untouched copy does not pass (each planted case below would fail for the wrong reason)"
  cat "$T/out"
  fails=$((fails + 1))
fi

plant "core reaches up" libvox/src/core/grid.cpp '#include "vox/trace/render.h"'
plant "io reaches up to sets" libvox/include/vox/io/grid_set.h '#include "vox/sets/voxelize_set.h"'
plant "trace reaches sideways" libvox/src/trace/render.cpp '#include "vox/export/voxel_mesh.h"'
plant "voxelize reads files" libvox/src/voxelize/voxelize.cpp '#include "vox/io/input_file.h"'
plant "into another stage's internals" libvox/src/export/voxel_mesh.cpp '#include "io/byte_codec.h"'
plant "public header includes a private one" libvox/include/vox/io/grid_file.h '#include "io/byte_codec.h"'
plant "angle brackets" libvox/src/core/math.cpp '#include <vox/trace/ray.h>'
plant "spaced directive" libvox/src/core/scene.cpp '  #  include "vox/import/import.h"' \
  'libvox/src/core/scene.cpp:2: #include "vox/import/import.h"'
plant "stage not in the order" libvox/src/render2/extra.cpp '#include "vox/core/math.h"' \
  'libvox/src/render2/extra.cpp:1: stage render2 is not in the order'
plant "file outside any stage" libvox/src/stray.cpp '#include "vox/core/math.h"' \
  'libvox/src/stray.cpp:1: not inside a stage folder'

echo "check_layers_plant.sh: $passes passed, $fails failed"
[ "$fails" = 0 ]
