#!/usr/bin/env python3
"""Turns the tradeoff CSV into docs/tradeoff.md and two gnuplot PNG plots.
Usage: tradeoff_report.py CSV SAT_SEARCH_TXT DOCS_DIR THREADS"""
import csv
import os
import subprocess
import sys
from collections import defaultdict

csv_path, sat_path, docs, threads = sys.argv[1:5]
rows = list(csv.DictReader(open(csv_path)))
for r in rows:
    for k in ("primitives", "res", "nx", "ny", "nz", "tests", "occupied", "references", "cells_added", "cells_missed",
              "refs_added", "refs_missed", "pixels_differing", "pixels"):
        r[k] = int(r[k])
    for k in ("voxelize_s", "tests_per_s", "primary_s", "shade_s", "cells_per_ray", "tests_per_ray"):
        r[k] = float(r[k])
scenes = list(dict.fromkeys(r["scene"] for r in rows))
methods = ["exact", "sat", "bbox", "center"]
images = os.path.join(docs, "images")

# Plot 1: voxelize time against error (refs added + missed, relative to exact refs), per method.
exact_refs = {(r["scene"], r["res"]): r["references"] for r in rows if r["method"] == "exact"}
# The default-heuristic rows repeat a sweep point's kind of data; plots use the sweep only.
sweep = [r for r in rows if r["res"] > 0]
data1 = os.path.join(images, "tradeoff_error.dat")
with open(data1, "w") as f:
    for m in methods:
        f.write(f'"{m}"\n')
        for r in sweep:
            if r["method"] != m:
                continue
            err = (r["refs_added"] + r["refs_missed"]) / max(1, exact_refs[(r["scene"], r["res"])])
            f.write(f'{r["voxelize_s"]:.6g} {max(err, 1e-6):.6g}\n')
        f.write("\n\n")
# Plot 2: shaded-image trace time against occupied-cell references per primitive, exact grids, per scene.
data2 = os.path.join(images, "tradeoff_trace.dat")
with open(data2, "w") as f:
    for s in scenes:
        f.write(f'"{s}"\n')
        for r in sweep:
            if r["scene"] == s and r["method"] == "exact":
                cells = r["nx"] * r["ny"] * r["nz"]
                f.write(f'{cells / max(1, r["primitives"]):.6g} {r["shade_s"]:.6g}\n')
        f.write("\n\n")
script = f"""
set terminal pngcairo size 900,600 noenhanced
set output '{images}/tradeoff_error.png'
set logscale xy
set xlabel 'voxelize seconds'
set ylabel 'references added + missed / exact references (1e-6 = none)'
set key outside
plot for [i=0:{len(methods)-1}] '{data1}' index i using 1:2 with points pt 7 title columnheader(1)
set output '{images}/tradeoff_trace.png'
set xlabel 'grid cells per primitive'
set ylabel 'trace seconds (shaded image, primary + shadow rays)'
plot for [i=0:{len(scenes)-1}] '{data2}' index i using 1:2 with linespoints title columnheader(1)
"""
try:
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    plots = True
except (OSError, subprocess.CalledProcessError) as e:
    print(f"tradeoff_report: no plots ({e})", file=sys.stderr)
    plots = False

out = []
out.append("# Speed and accuracy: overlap methods and grid resolution\n")
out.append("Measured by `bench/tradeoff.sh` (build with `-DVOX_BENCH=ON`), on this project's 2-core machine with "
           f"{threads} threads; raw numbers in `docs/tradeoff.csv`. Voxelize times are of voxelization alone (in "
           "process, no file I/O); trace times are of a shaded image (primary and shadow rays) through the grid. "
           "`added`/`missed` count (cell, primitive) references relative to `exact`; `px diff` counts pixels of the "
           "shaded image that differ from the brute-force image (no grid).\n")
if plots:
    out.append("![time against error](images/tradeoff_error.png)\n")
    out.append("![trace time against cells per primitive](images/tradeoff_trace.png)\n")
for s in scenes:
    srows = [r for r in rows if r["scene"] == s]
    out.append(f"\n## {s} ({srows[0]['primitives']} primitives)\n")
    out.append("| res | dims | method | voxelize ms | tests/s (M) | occupied | refs | refs added | refs missed | "
               "trace ms | cells/ray | tests/ray | px diff |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in srows:
        res = r['res'] if r['res'] > 0 else 'default'
        out.append(f"| {res} | {r['nx']}x{r['ny']}x{r['nz']} | {r['method']} | {1000*r['voxelize_s']:.2f} | "
                   f"{r['tests_per_s']/1e6:.1f} | {r['occupied']} | {r['references']} | {r['refs_added']} | "
                   f"{r['refs_missed']} | {1000*r['shade_s']:.1f} | {r['cells_per_ray']:.1f} | "
                   f"{r['tests_per_ray']:.1f} | {r['pixels_differing']} |")

# Best resolution per scene (fastest shaded trace with an exact grid) against the default heuristic's cells/prim.
out.append("\n## Resolution: best per scene\n")
out.append("The fastest resolution for tracing each scene with an `exact` grid, as grid cells per bounded primitive; "
           "the default heuristic (`vox::defaultDims`, `kCellsPerPrimitive` in `voxelize.h`) aims at a fixed number "
           "of cells per primitive.\n")
out.append("| scene | best res | cells per primitive | trace ms at best | default dims | trace ms at default | default / best | trace ms at each res |")
out.append("|---|---|---|---|---|---|---|---|")
ratios = []
for s in scenes:
    ex = [r for r in rows if r["scene"] == s and r["method"] == "exact" and r["res"] > 0]
    default = [r for r in rows if r["scene"] == s and r["method"] == "exact" and r["res"] == 0]
    best = min(ex, key=lambda r: r["shade_s"])
    cpp = best["nx"] * best["ny"] * best["nz"] / max(1, best["primitives"])
    ratios.append(cpp)
    allres = ", ".join(f"{r['res']}: {1000*r['shade_s']:.1f}" for r in ex)
    if default:
        d = default[0]
        dd = f"{d['nx']}x{d['ny']}x{d['nz']} | {1000*d['shade_s']:.1f} | {d['shade_s']/max(best['shade_s'],1e-9):.2f}"
    else:
        dd = "- | - | -"
    out.append(f"| {s} | {best['res']} | {cpp:.2f} | {1000*best['shade_s']:.1f} | {dd} | {allres} |")
ratios.sort()
out.append(f"\nMedian best cells per primitive over these scenes: {ratios[len(ratios)//2]:.2f}.\n")

# Method summary over all scenes and resolutions.
out.append("\n## Methods in sum\n")
out.append("| method | total voxelize s | refs added | refs missed | images differing from brute force |")
out.append("|---|---|---|---|---|")
for m in methods:
    mr = [r for r in sweep if r["method"] == m]
    out.append(f"| {m} | {sum(r['voxelize_s'] for r in mr):.3f} | {sum(r['refs_added'] for r in mr)} | "
               f"{sum(r['refs_missed'] for r in mr)} | {sum(1 for r in mr if r['pixels_differing'] > 0)} of {len(mr)} |")

out.append("\n## Does `sat` miss cells?\n")
out.append("`bench/sat_search` tests adversarial triangle-cell pairs (contacts on faces, edges and corners, one ulp "
           "beside them, triangles in cell planes, degenerate and tiny triangles, scales 1e-6 to 1e6, offsets to "
           "1e7) with both tests:\n")
out.append("```\n" + open(sat_path).read().rstrip() + "\n```\n")
open(os.path.join(docs, "tradeoff.md"), "w").write("\n".join(out) + "\n")
print(f"wrote {os.path.join(docs, 'tradeoff.md')}")
