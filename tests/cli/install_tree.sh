#!/usr/bin/env bash
# cmake --install gives a tree a C++ user builds against (issue 36): the tools, libvox.a, the public headers (each
# compile against the tree alone; the internal ones are not there), the CMake package and the pkg-config file. A consumer program
# (tests/install/consumer.cpp: voxelize a triangle, write a grid file, read it back) is built against the tree twice,
# through find_package(libvox CONFIG) and through pkg-config, and run; the installed vox-trace writes a PNG through
# the OpenImageIO module it finds in the tree's library folder.
# Usage: install_tree.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; echo "FAIL: install"; exit 1; }

for tool in vox-voxelize vox-info vox-trace vox-export; do
  [ -x "$prefix/bin/$tool" ] || fail "bin/$tool not installed"
done
libdir=$(find "$prefix" -name libvox.a -printf '%h\n' | head -1)
[ -n "$libdir" ] || fail "libvox.a not installed"
[ -f "$libdir/libvox_oiio.so" ] || fail "libvox_oiio.so not beside libvox.a"
[ -f "$libdir/cmake/libvox/libvoxConfig.cmake" ] || fail "no CMake package in $libdir/cmake/libvox"
[ -f "$libdir/pkgconfig/libvox.pc" ] || fail "no libvox.pc in $libdir/pkgconfig"
for h in core/varint.h core/checked_math.h core/cell_range.h core/tool.h; do
  [ ! -e "$prefix/include/vox/$h" ] || fail "internal header vox/$h installed"
done
[ -f "$prefix/include/vox/voxelize/voxelize.h" ] || fail "vox/voxelize/voxelize.h not installed"
# Nothing installed points back into the source or build tree.
if grep -rlI -e "$src/libvox" -e "$build" "$prefix/include" "$libdir/cmake" "$libdir/pkgconfig" >"$tmp/leaks"; then
  fail "installed files name the source or build tree: $(cat "$tmp/leaks")"
fi

# The public headers compile against the installed tree alone, all in one file (none needs a header that was left out
# or a file of the source tree; one compile of each would take 43 s).
n=0
: >"$tmp/h.cpp"
while IFS= read -r h; do
  echo "#include \"${h#"$prefix/include/"}\"" >>"$tmp/h.cpp"
  n=$((n + 1))
done < <(find "$prefix/include/vox" -name '*.h' | sort)
echo 'int main() { return 0; }' >>"$tmp/h.cpp"
g++ -std=c++20 -fsyntax-only -I"$prefix/include" "$tmp/h.cpp" 2>"$tmp/h.err" || fail "the public headers do not compile: $(head -c 600 "$tmp/h.err")"
[ "$n" -ge 30 ] || fail "only $n public headers"

# find_package route: a CMake project of its own, outside both trees.
cmake -S "$src/tests/install" -B "$tmp/cmake-build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/cmake.log" 2>&1 || fail "consumer configure: $(tail -20 "$tmp/cmake.log")"
cmake --build "$tmp/cmake-build" >"$tmp/cmake-build.log" 2>&1 || fail "consumer build (CMake): $(tail -20 "$tmp/cmake-build.log")"
out=$("$tmp/cmake-build/consumer" "$tmp/a.vgrid") || fail "consumer (CMake) exited $?"
[[ $out == "consumer: "*" occupied cells of 64 written and read back" ]] || fail "consumer (CMake) printed '$out'"
"$prefix/bin/vox-info" "$tmp/a.vgrid" >/dev/null || fail "installed vox-info cannot read the consumer's grid"

# pkg-config route: the compiler line alone.
flags=$(PKG_CONFIG_PATH="$libdir/pkgconfig" pkg-config --cflags --libs libvox) || fail "pkg-config libvox"
g++ -O1 -o "$tmp/consumer-pc" "$src/tests/install/consumer.cpp" $flags 2>"$tmp/pc.err" || fail "consumer build (pkg-config): $(head -c 600 "$tmp/pc.err")"
out=$("$tmp/consumer-pc" "$tmp/b.vgrid") || fail "consumer (pkg-config) exited $?"
[[ $out == "consumer: "*" occupied cells of 64 written and read back" ]] || fail "consumer (pkg-config) printed '$out'"
cmp -s "$tmp/a.vgrid" "$tmp/b.vgrid" || fail "the two consumers wrote different grid files"

# The installed tools run from the tree, images included (the OpenImageIO module found in the tree's libdir).
"$prefix/bin/vox-voxelize" "$src/scenes/scene5_02_spheres.txt" -o "$tmp/s.vgrid" -q || fail "installed vox-voxelize"
"$prefix/bin/vox-trace" "$tmp/s.vgrid" -o "$tmp/s.png" --size 32 32 -q || fail "installed vox-trace"
[ -s "$tmp/s.png" ] || fail "installed vox-trace wrote no PNG"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "install_tree: $n public headers, consumer by CMake and pkg-config, tools run from the tree"
