#!/usr/bin/env bash
# Installs, builds and runs every test. Usage: scripts/test.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh" --clients
build=$(realpath -m "${1:-$root/build}")  # absolute: the Python stage runs from tests/python
VOX_SEED_DIR=$("$root/scripts/seed-dir.sh")
export VOX_SEED_DIR
shift || true
# The Python package is built and tested only without the sanitizers: its module, loaded by an uninstrumented
# python3, would need libasan preloaded into the interpreter (the sanitizer pass tests the same library code).
python=ON
[[ " $* " == *" -DVOX_SANITIZE=ON "* ]] && python=OFF
"$root/scripts/build.sh" "$build" -DVOX_TESTS=ON -DVOX_PYTHON=$python "$@"
echo "test.sh: $build built at $SECONDS s" >&2
cd "$build"
# VOX_CTEST_EXCLUDE: a regular expression of tests to leave out (CI's sanitizer pass leaves out the external clients,
# whose files the release pass already checked).
ctest --output-on-failure -j2 --timeout 900 ${VOX_CTEST_EXCLUDE:+-E "$VOX_CTEST_EXCLUDE"}
if [ "$python" = ON ]; then
  # The Python stage (docs/python.md): the package installed as a user installs it (offline, into a venv that sees
  # Debian's numpy), its module taken from this build folder, then its tests against the tools built here.
  venv=$build/python-venv
  [ -x "$venv/bin/python" ] || /usr/bin/python3 -m venv --system-site-packages "$venv"
  LIBVOX_BUILD_DIR=$build "$venv/bin/pip" install --quiet --no-build-isolation --no-index --force-reinstall \
    --no-deps "$root/python"
  echo "test.sh: Python package installed at $SECONDS s" >&2
  (cd "$root/tests/python" && LIBVOX_TOOLS_DIR=$build "$venv/bin/python" -m pytest -q -p no:cacheprovider .)
  echo "test.sh: Python tests passed at $SECONDS s" >&2
fi
