#!/usr/bin/env bash
# Prints the folder of the seed scenes that tests, benchmarks and fuzz seeds read: $VOX_SEED_DIR when set, else
# ../shared/seed-scenes beside this clone, else the one beside the repository this clone was made from (a local clone
# kept elsewhere, such as a temporary folder). When none exists it prints the first, so that the error names it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
if [ -n "${VOX_SEED_DIR:-}" ]; then
  echo "$VOX_SEED_DIR"
  exit 0
fi
beside=$root/../shared/seed-scenes
origin=$(git -C "$root" remote get-url origin 2>/dev/null || true)
origin=${origin#file://}
for dir in "$beside" ${origin:+"$origin/../shared/seed-scenes"}; do
  case $dir in /*) ;; *) continue ;; esac  # a URL or a relative remote says nothing about this machine's folders
  if [ -d "$dir/6837/scenes" ]; then
    (cd "$dir" && pwd)
    exit 0
  fi
done
echo "$beside"
