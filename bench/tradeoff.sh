#!/usr/bin/env bash
# Runs the speed-accuracy benchmark and writes docs/tradeoff.csv, docs/images/tradeoff_*.png and docs/tradeoff.md.
# Usage: bench/tradeoff.sh [BUILD_DIR]   (build with -DVOX_BENCH=ON; needs gnuplot-nox for the plots)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
threads=${THREADS:-$(nproc)}
mkdir -p "$root/docs/images"
"$build/bench/tradeoff" "$root/docs/tradeoff.csv" --threads "$threads" ${TRADEOFF_ARGS:-}
"$build/bench/sat_search" "${SAT_PAIRS:-200000}" >"$root/docs/sat_search.txt"
python3 "$root/bench/tradeoff_report.py" "$root/docs/tradeoff.csv" "$root/docs/sat_search.txt" "$root/docs" "$threads"
