#!/usr/bin/env python3
"""Turns the tradeoff CSV into docs/tradeoff.md and two matplotlib PNG plots (docs/images/tradeoff_*.png, their
data written beside them as .dat files).
Usage: tradeoff_report.py CSV SAT_SEARCH_TXT DOCS_DIR THREADS"""
import csv
import os
import math
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
points1 = {m: [] for m in methods}
with open(data1, "w") as f:
    f.write("# voxelize seconds, (references added + missed) / exact references (0 = none), per method; "
            "from docs/tradeoff.csv by bench/tradeoff_report.py\n")
    for m in methods:
        f.write(f'"{m}"\n')
        for r in sweep:
            if r["method"] != m:
                continue
            err = (r["refs_added"] + r["refs_missed"]) / max(1, exact_refs[(r["scene"], r["res"])])
            points1[m].append((r["voxelize_s"], err))
            f.write(f'{r["voxelize_s"]:.6g} {err:.6g}\n')
        f.write("\n\n")
# Plot 2: shaded-image trace time against grid cells per primitive, exact grids, per scene.
data2 = os.path.join(images, "tradeoff_trace.dat")
points2 = {s: [] for s in scenes}
defaults2 = {}
with open(data2, "w") as f:
    f.write("# grid cells per primitive, shaded-image trace seconds, exact grids, per scene; "
            "from docs/tradeoff.csv by bench/tradeoff_report.py\n")
    for s in scenes:
        f.write(f'"{s}"\n')
        for r in sweep:
            if r["scene"] == s and r["method"] == "exact":
                cells = r["nx"] * r["ny"] * r["nz"]
                points2[s].append((cells / max(1, r["primitives"]), r["shade_s"]))
                f.write(f'{cells / max(1, r["primitives"]):.6g} {r["shade_s"]:.6g}\n')
        f.write("\n\n")
        for r in rows:
            if r["scene"] == s and r["method"] == "exact" and r["res"] == 0:
                defaults2[s] = (r["nx"] * r["ny"] * r["nz"] / max(1, r["primitives"]), r["shade_s"])


def draw_plots():
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style as ps

    footnote = (f"bench/tradeoff.sh ({threads} threads, 256x256 shaded image); data: docs/tradeoff.csv, "
                "docs/images/tradeoff_*.dat; redraw: python3 bench/tradeoff_report.py docs/tradeoff.csv "
                f"docs/sat_search.txt docs {threads}")
    # Plot 1.
    fig, ax = ps.figure(5.0)
    errors = [e for m in methods for _, e in points1[m] if e > 0]
    floor = 10 ** (math.floor(math.log10(min(errors))) - 1) if errors else 1e-6
    styles = {"exact": ("o", 60, "#1f77b4"), "sat": ("x", 40, "#d62728"), "bbox": ("s", 30, "#2ca02c"),
              "center": ("^", 30, "#9467bd")}
    for m in methods:
        marker, size, colour = styles[m]
        xs = [t for t, _ in points1[m]]
        ys = [e if e > 0 else floor for _, e in points1[m]]
        wrong = sum(1 for _, e in points1[m] if e > 0)
        filled = {"facecolors": "none", "edgecolors": colour} if marker in ("o", "s", "^") else {"color": colour}
        ax.scatter(xs, ys, s=size, marker=marker, **filled,
                   label=f"{m}: {wrong} of {len(xs)} grids differ from exact")
    ps.log_axis(ax, "x")
    ps.log_axis(ax, "y", zero_at=floor)
    ax.set_ylim(floor / 2.5, None)
    ax.set_xlabel("voxelize time (s, voxelization alone, per scene and resolution)")
    ax.set_ylabel("references added + missed / exact's references")
    ax.set_title("Overlap methods: voxelize time against error, 9 scenes x 6 resolutions")
    ax.legend(loc="upper left")
    ps.footnote(fig, footnote)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    ps.save(fig, os.path.join(images, "tradeoff_error.png"))
    # Plot 2.
    fig, ax = ps.figure(5.2)
    cmap = ps.plt.get_cmap("tab10")
    for i, s in enumerate(scenes):
        pts = sorted(points2[s])
        ax.plot([c for c, _ in pts], [t for _, t in pts], marker="o", markersize=4, color=cmap(i % 10), label=s)
        if s in defaults2:
            ax.scatter([defaults2[s][0]], [defaults2[s][1]], marker="*", s=130, color=cmap(i % 10),
                       edgecolors="black", linewidths=0.6, zorder=3)
    ax.scatter([], [], marker="*", s=130, color="white", edgecolors="black", label="default grid (vox-voxelize)")
    ps.log_axis(ax, "x")
    ps.log_axis(ax, "y")
    ax.set_xlabel("grid cells per primitive (cells / primitives)")
    ax.set_ylabel("trace time (s, 256x256 shaded image)")
    ax.set_title("Exact grids: trace time against grid resolution, per scene")
    ax.legend(loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=7.5)
    ps.footnote(fig, footnote)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    ps.save(fig, os.path.join(images, "tradeoff_trace.png"))


try:
    draw_plots()
    plots = True
except ImportError as e:
    print(f"tradeoff_report: no plots ({e}; Debian: python3-matplotlib)", file=sys.stderr)
    plots = False

out = []
out.append("# Speed and accuracy: overlap methods and grid resolution\n")
out.append("What this page is for: which overlap method and grid resolution to pick, from the cost and the error of "
           "each measured on 9 scenes at 6 resolutions (generated by `bench/tradeoff_report.py`; edit that, not "
           "this page).\n")
out.append("Measured by `bench/tradeoff.sh` (build with `-DVOX_BENCH=ON`), on this project's 2-core machine with "
           f"{threads} threads; raw numbers in `docs/tradeoff.csv`. Voxelize times are of voxelization alone (in "
           "process, no file I/O); trace times are of a shaded image (primary and shadow rays) through the grid. "
           "`added`/`missed` count (cell, primitive) references relative to `exact`; `px diff` counts pixels of the "
           "shaded image that differ from the brute-force image (no grid).\n")
out.append("The volume each method's cells add up to, against the exact volume fractions: "
           "[volume-error.md](volume-error.md). The distance error of OpenVDB's level set against libvox's exact "
           "signed distances: [distance.md](distance.md), \"Cost, and OpenVDB's level set on the same voxels\".\n")
if plots:
    out.append("Both plots are redrawn from the stored numbers, without measuring again, by "
               f"`python3 bench/tradeoff_report.py docs/tradeoff.csv docs/sat_search.txt docs {threads}` "
               "(their data: `docs/images/tradeoff_error.dat`, `tradeoff_trace.dat`); `bash bench/tradeoff.sh` "
               "measures again and redraws.\n")
    out.append("![Overlap methods: voxelize time against error](images/tradeoff_error.png)\n")
    out.append("![Exact grids: trace time against grid resolution, per scene](images/tradeoff_trace.png)\n")
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
