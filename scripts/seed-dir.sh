#!/usr/bin/env bash
# Prints the folder of the seed scenes that tests, benchmarks and fuzz seeds read: $VOX_SEED_DIR when set (an
# override, for a copy kept elsewhere), else data/ of this clone, where they live (data/README.md: origins, licences).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
echo "${VOX_SEED_DIR:-$root/data}"
