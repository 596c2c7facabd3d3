#!/usr/bin/env bash
# A real client: assimp 5.2's command line (`assimp info`, the Open Asset Import Library behind many viewers and
# engines) reads every format, face mode and colour mode that vox-export writes, for a scene of three materials
# whose voxel surface has colour seams (tests/data/two_materials.obj). Checks: exit 0 and the mesh's triangle
# count (assimp triangulates); with colours, that assimp sees them: materials with distinct diffuse colours for
# OBJ and glTF, vertex colours for PLY (from `assimp dump`). Issue 10: assimp refused the "COFF" files (exit 3)
# and failed to triangulate merged polygons with collinear vertices. Skips (exit 0) when assimp is missing; CI
# installs it (scripts/install-deps.sh --clients).
# Usage: export_assimp.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
if ! command -v assimp >/dev/null; then
  echo "SKIP: assimp (assimp-utils) not installed"
  exit 0
fi
[ -x "$build/vox-voxelize" ] && [ -x "$build/vox-export" ] ||
  { echo "SKIP: vox-voxelize or vox-export not built"; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$build/vox-voxelize" "$src/tests/data/two_materials.obj" -o "$tmp/g.vgrid" --grid 16 10 10 --quiet ||
  { echo "FAIL: voxelize"; exit 1; }
checked=0
for faces in all exposed merged; do
  for color in material count none; do
    # Triangles the mesh has once triangulated: those of the binary STL export (84-byte header, 50 per triangle).
    "$build/vox-export" "$tmp/g.vgrid" -o "$tmp/t.stl" --faces "$faces" --color "$color" --quiet ||
      { fail "export $faces $color stl"; continue; }
    triangles=$((($(stat -c %s "$tmp/t.stl") - 84) / 50))
    for ext in ply obj off stl glb gltf; do
      name="$faces-$color.$ext"
      mesh="$tmp/$name"
      "$build/vox-export" "$tmp/g.vgrid" -o "$mesh" --faces "$faces" --color "$color" --quiet ||
        { fail "export $name"; continue; }
      (cd "$tmp" && timeout 60 assimp info "$mesh") >"$tmp/info.log" 2>&1
      rc=$?
      if [ "$rc" != 0 ] || ! grep -q "Importing file .*OK" "$tmp/info.log"; then
        fail "$name: assimp info exit $rc: $(grep -m2 -i 'error\|fail' "$tmp/info.log" | tr '\n' ' ')"
        continue
      fi
      checked=$((checked + 1))
      got=$(sed -n 's/^Faces: *//p' "$tmp/info.log")
      [ "$got" = "$triangles" ] || fail "$name: assimp sees $got faces, expected $triangles triangles"
      grep -qi "triangulate\|no ear" "$tmp/info.log" &&
        fail "$name: $(grep -m1 -i 'triangulate\|no ear' "$tmp/info.log")"
      [ "$color" = none ] && continue
      case $ext in
        obj | glb | gltf)
          # Distinct diffuse colours among the materials (the "$clr.diffuse" property of each material), other
          # than the white of a default material.
          (cd "$tmp" && assimp dump "$mesh" "$tmp/dump.xml" -s) >/dev/null 2>&1
          colors=$(grep -A3 'key="\$clr.diffuse"' "$tmp/dump.xml" 2>/dev/null |
            grep -o '[0-9.e+-]\+ [0-9.e+-]\+ [0-9.e+-]\+' | grep -v '^1.000000 1.000000 1.000000$' | sort -u | wc -l)
          [ "$colors" -ge 2 ] || fail "$name: assimp sees $colors distinct material colours"
          ;;
        ply)
          (cd "$tmp" && assimp dump "$mesh" "$tmp/dump.xml" -s) >/dev/null 2>&1
          grep -q '<Colors' "$tmp/dump.xml" 2>/dev/null || fail "$name: assimp sees no vertex colours"
          ;;
      esac
    done
  done
done
echo "export_assimp: $checked files read by assimp $(assimp version 2>/dev/null | grep -o 'v[0-9.]*' | head -1)"
if [ "$failures" -gt 0 ]; then echo "$failures failure(s)"; exit 1; fi
echo "export_assimp: every format and colour mode reads without error"
