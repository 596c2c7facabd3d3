#!/usr/bin/env bash
# The trace library must hold no fused multiply-add: its grid walk, float filter and triangle tests are compiled in
# copies for several instruction sets (target_clones; the x86-64-v4 copy may use FMA instructions), and bit-identical
# hits across copies and against the brute force rely on -ffp-contract=off keeping every a * b + c two roundings.
# Usage: no_fused_multiply_add.sh BUILD_DIR SOURCE_DIR
set -u
BUILD=$1
lib="$BUILD/libvox.a"
[ -f "$lib" ] || { echo "FAIL: $lib not found"; exit 1; }
command -v objdump > /dev/null || { echo "FAIL: objdump (binutils) not found"; exit 1; }
# The tracing code's objects (the whole library takes minutes to disassemble under the sanitizers).
members="accel.cpp.o float_filter.cpp.o intersect.cpp.o render.cpp.o shade.cpp.o trace_packet.cpp.o traverse.cpp.o"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && ar x "$lib" $members) || { echo "FAIL: $lib lacks one of $members"; exit 1; }
objs=$(cd "$work" && objdump -d --no-show-raw-insn $members)
# Clones for AVX-512 must exist where the compiler makes them (g++ on x86-64; clang builds get two copies, see
# traverse.cpp), or this test would check nothing of them.
gnu=$(grep -ls 'CMAKE_CXX_COMPILER_ID "GNU"' "$BUILD"/CMakeFiles/*/CMakeCXXCompiler.cmake)
if [ "$(uname -m)" = x86_64 ] && [ -n "$gnu" ] && ! grep -q "x86_64_v4" <<< "$objs"; then
  echo "FAIL: no x86-64-v4 copy of the walk in $lib"
  exit 1
fi
fma=$(grep -E "\s(vfn?m(add|sub)[0-9]{3}[ps][sd])\s" <<< "$objs" | head -5)
if [ -n "$fma" ]; then
  echo "FAIL: fused multiply-add instructions in $lib:"
  echo "$fma"
  exit 1
fi
echo "no fused multiply-add in the tracing code of $lib"
