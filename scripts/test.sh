#!/usr/bin/env bash
# Installs, builds and runs every test. Usage: scripts/test.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh" --clients
build=${1:-$root/build}
VOX_SEED_DIR=$("$root/scripts/seed-dir.sh")
export VOX_SEED_DIR
shift || true
"$root/scripts/build.sh" "$build" -DVOX_TESTS=ON "$@"
echo "test.sh: $build built at $SECONDS s" >&2
cd "$build"
# VOX_CTEST_EXCLUDE: a regular expression of tests to leave out (CI's sanitizer pass leaves out the external clients,
# whose files the release pass already checked).
ctest --output-on-failure -j2 --timeout 900 ${VOX_CTEST_EXCLUDE:+-E "$VOX_CTEST_EXCLUDE"}
