#!/usr/bin/env bash
# Fails (exit 1) naming each C++ file that clang-format (.clang-format at the root) would change.
# Usage: scripts/check-format.sh    Fix: git ls-files '*.cpp' '*.h' | xargs clang-format -i
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bad=0
while IFS= read -r f; do
  clang-format --dry-run -Werror "$f" >/dev/null 2>&1 || { echo "check-format.sh: $f is not formatted" >&2; bad=1; }
done < <(git ls-files '*.cpp' '*.h')
exit $bad
