#!/usr/bin/env bash
# Runs the speed-accuracy benchmark and writes docs/tradeoff.csv, docs/images/tradeoff_*.png and docs/tradeoff.md.
# Usage: bench/tradeoff.sh [BUILD_DIR]   (build with -DVOX_BENCH=ON; the plots need Debian's python3-matplotlib)
# Redraw the plots and the page from the stored numbers without measuring:
#   python3 bench/tradeoff_report.py docs/tradeoff.csv docs/sat_search.txt docs 2
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
threads=${THREADS:-$(nproc)}
mkdir -p "$root/docs/images"
"$build/bench/tradeoff" "$root/docs/tradeoff.csv" --threads "$threads" ${TRADEOFF_ARGS:-}
"$build/bench/sat_search" "${SAT_PAIRS:-200000}" >"$root/docs/sat_search.txt"
"${PYTHON:-/usr/bin/python3}" "$root/bench/tradeoff_report.py" "$root/docs/tradeoff.csv" "$root/docs/sat_search.txt" "$root/docs" "$threads"
