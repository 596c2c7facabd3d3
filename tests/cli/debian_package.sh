#!/usr/bin/env bash
# cpack -G DEB makes a Debian package users install as they install everything else (issue 36): it holds the tools,
# the library, the public headers, the CMake package, the pkg-config file and the man pages; its Depends name the
# Debian 12 runtime packages (dpkg-shlibdeps), which apt resolves; unpacked (dpkg-deb -x, no root needed), its vox-voxelize runs.
# Usage: debian_package.sh BUILD_DIR SOURCE_DIR
set -u
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
command -v dpkg-shlibdeps >/dev/null || { echo "FAIL: dpkg-shlibdeps missing (dpkg-dev)"; exit 1; }
(cd "$tmp" && cpack -G DEB --config "$build/CPackConfig.cmake" -B "$tmp/out") >"$tmp/cpack.log" 2>&1 ||
  { tail -30 "$tmp/cpack.log"; echo "FAIL: cpack"; exit 1; }
deb=$(find "$tmp/out" -maxdepth 1 -name 'libvox_*.deb' | head -1)
[ -n "$deb" ] || { echo "FAIL: no .deb in $tmp/out"; ls "$tmp/out"; exit 1; }
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$build/CMakeCache.txt")  # project(libvox VERSION ...)
[ -n "$version" ] || { echo "FAIL: no CMAKE_PROJECT_VERSION in $build/CMakeCache.txt"; exit 1; }
[ "$(dpkg-deb -f "$deb" Package)" = libvox ] || fail "Package: $(dpkg-deb -f "$deb" Package)"
[ "$(dpkg-deb -f "$deb" Version)" = "$version" ] || fail "Version: $(dpkg-deb -f "$deb" Version), not $version"
depends=$(dpkg-deb -f "$deb" Depends)
# The libraries the tools and the OpenImageIO module link, by their Debian 12 package names.
for p in libc6 libstdc++6 libtbb12 libopenvdb10.0 libopenmesh1 libimath-3-1-29 libgmp10 libopenimageio2.4 zlib1g; do
  [[ ", $depends," == *", $p "* || ", $depends," == *", $p,"* ]] || fail "Depends lacks $p: $depends"
done
dpkg-deb -c "$deb" >"$tmp/contents"
for f in ./usr/bin/vox-voxelize ./usr/bin/vox-info ./usr/bin/vox-trace ./usr/bin/vox-export ./usr/include/vox/voxelize/voxelize.h \
    ./usr/include/vox/io/grid_file.h ./usr/share/man/man1/vox-voxelize.1 ./usr/share/man/man1/vox-trace.1; do
  grep -q " $f\$" "$tmp/contents" || fail "the package lacks $f"
done
for f in libvox.a libvox_oiio.so cmake/libvox/libvoxConfig.cmake cmake/libvox/libvoxTargets.cmake pkgconfig/libvox.pc; do
  grep -Eq " \./usr/lib/([a-z0-9_-]+/)?$f\$" "$tmp/contents" || fail "the package lacks usr/lib/.../$f"
done
! grep -q "vox/core/varint.h" "$tmp/contents" || fail "the package holds an internal header"

# apt resolves its Depends from Debian 12's archive (a simulation: no root, nothing installed).
apt-get install -s "$deb" >"$tmp/apt.log" 2>&1 && grep -q "^Inst libvox " "$tmp/apt.log" ||
  fail "apt-get install -s refuses the package: $(tail -5 "$tmp/apt.log")"
dpkg-deb -x "$deb" "$tmp/root"
out=$("$tmp/root/usr/bin/vox-voxelize" --version 2>&1) || fail "unpacked vox-voxelize --version exited $?"
[ "$out" = "libvox $version" ] || fail "unpacked vox-voxelize --version printed '$out'"
"$tmp/root/usr/bin/vox-voxelize" "$src/scenes/scene5_02_spheres.txt" -o "$tmp/s.vgrid" -q || fail "unpacked vox-voxelize"
"$tmp/root/usr/bin/vox-trace" "$tmp/s.vgrid" -o "$tmp/s.png" --size 16 16 -q || fail "unpacked vox-trace (OpenImageIO module)"
# help2man writes each flag with escaped dashes (\fB\-\-fill\fR): the page holds the tool's own --help.
grep -qF -- '\-\-fill' "$tmp/root/usr/share/man/man1/vox-voxelize.1" || fail "man page of vox-voxelize lacks --fill"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "debian_package: $(basename "$deb"), Depends: $depends"
