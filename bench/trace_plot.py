#!/usr/bin/env python3
"""Rays per second of the grid against Embree 3, per ray kind: runs build/bench/bench_trace (primary rays, then the
incoherent sets), keeps its output and a CSV beside the plot, and draws docs/images/trace_vs_embree.png.

Usage: bench/trace_plot.py [--build DIR] [--threads N] [--size N] [--reps N]   (measure, then plot)
       bench/trace_plot.py --plot-only                                        (plot the stored CSV again)
Needs a build with -DVOX_BENCH=ON and Debian's python3-matplotlib. With the defaults (1 thread, 1024x1024 primary
rays, 5 rounds) the two runs take about a minute of CPU.

The ratios are what to read: bench_trace times Embree and ours in turns within one run, so a burst of load on a
shared machine weighs on both alike. The absolute rays per second are one run on whatever machine ran it.
Ray kinds (bench/bench_trace.cpp, docs/trace.md): primary rays of a 1024x1024 image, one at a time (traceRay against
rtcIntersect1) and in 8x8 pixel packets as vox-trace renders (tracePacket against rtcIntersect1); then from their first
hits: reflection (mirror rays, nearest hit), hemisphere (cosine-weighted, nearest hit), ao (the same directions,
occlusion within a fifth of the bounds' diagonal), shadow (occlusion towards a point light), one at a time against
rtcIntersect1 / rtcOccluded1.
"""
import argparse
import csv
import datetime
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IMAGES = os.path.join(ROOT, "docs", "images")
CSV = os.path.join(IMAGES, "trace_vs_embree.csv")
RAW = os.path.join(IMAGES, "trace_vs_embree.txt")
PNG = os.path.join(IMAGES, "trace_vs_embree.png")
KINDS = ["primary", "primary, packets", "reflection", "hemisphere", "ao", "shadow"]
SCENE_NAMES = {"bunny_40k.obj": "40k course bunny", "bun_zipper.ply": "69k Stanford bunny",
               "sheencloth_115k.obj": "115k SheenCloth", "SheenCloth.gltf": "115k SheenCloth"}


def parse(text):
    """Rows (scene, kind, embree Mrays/s, ours Mrays/s, ours / embree) from bench_trace's two outputs."""
    rows = []
    scene = None
    embree1 = None
    for line in text.splitlines():
        m = re.match(r"^(\S+): \d+ triangles", line)
        if m:
            scene = SCENE_NAMES.get(m.group(1), m.group(1))
            continue
        m = re.match(r"^\s+embree rtcIntersect1:\s+([\d.]+) Mrays/s", line)
        if m:
            embree1 = float(m.group(1))
            continue
        m = re.match(r"^\s+(traceRay|tracePacket):\s+([\d.]+) Mrays/s\s+ratio vs rtcIntersect1 ([\d.]+)", line)
        if m:
            kind = "primary" if m.group(1) == "traceRay" else "primary, packets"
            rows.append((scene, kind, embree1, float(m.group(2)), float(m.group(3))))
            continue
        m = re.match(r"^\s+(reflection|hemisphere|ao|shadow)\s+\w+\s+([\d.]+) M\s+([\d.]+) M\s+([\d.]+)", line)
        if m:
            rows.append((scene, m.group(1), float(m.group(2)), float(m.group(3)), float(m.group(4))))
    return rows


def measure(args):
    bench = os.path.join(args.build, "bench", "bench_trace")
    common = ["--threads", str(args.threads), "--size", str(args.size), "--reps", str(args.reps)]
    commands = [[bench, *common, "--factor", "3"], [bench, "--incoherent", *common]]
    with open("/proc/loadavg") as f:
        load = f.read().split()[0]
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    header = (f"# {datetime.date.today()}, commit {commit}, {os.cpu_count()} cores, load average {load} at the start\n")
    text = ""
    for cmd in commands:
        shown = " ".join(["build/bench/bench_trace"] + cmd[1:])
        print("running:", shown, flush=True)
        p = subprocess.run(cmd, capture_output=True, text=True)
        text += f"$ {shown}\n{p.stdout}\n"
        if p.returncode != 0:  # kept if every line came out: the rows are checked below
            print(f"trace_plot: {shown} exited with {p.returncode} after printing:\n{p.stdout}", file=sys.stderr)
            text += f"(exit status {p.returncode})\n"
    with open(RAW, "w") as f:
        f.write(header + text)
    rows = parse(text)
    scenes = {r[0] for r in rows}
    if len(rows) != len(scenes) * len(KINDS):
        sys.exit(f"trace_plot: {len(rows)} rows for {len(scenes)} scenes, not {len(KINDS)} each; see the output above")
    with open(CSV, "w", newline="") as f:
        f.write(header)
        f.write("# " + " ; ".join(" ".join(["build/bench/bench_trace"] + c[1:]) for c in commands) + "\n")
        w = csv.writer(f)
        w.writerow(["scene", "ray_kind", "embree_mrays_per_s", "ours_mrays_per_s", "ours_over_embree"])
        w.writerows(rows)
    print(f"wrote {RAW} and {CSV}")


def load_csv():
    with open(CSV) as f:
        lines = [line for line in f if not line.startswith("#")]
    comments = [line[2:].strip() for line in open(CSV) if line.startswith("#")]
    rows = list(csv.DictReader(lines))
    return rows, comments


def plot():
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style as ps

    rows, comments = load_csv()
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    kinds = [k for k in KINDS if any(r["ray_kind"] == k for r in rows)]
    fig, ax = ps.figure(4.8)
    width = 0.8 / len(scenes)
    colours = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd"]
    for s, scene in enumerate(scenes):
        values = []
        for k in kinds:
            match = [r for r in rows if r["scene"] == scene and r["ray_kind"] == k]
            values.append(float(match[0]["ours_over_embree"]) if match else 0)
        xs = [i + (s - (len(scenes) - 1) / 2) * width for i in range(len(kinds))]
        bars = ax.bar(xs, values, width, label=scene, color=colours[s % len(colours)])
        ax.bar_label(bars, fmt="%.2f", fontsize=7, padding=1)
    ax.axhline(1.0, color="black", linewidth=1, linestyle="--")
    ax.text(-0.45, 1.02, "Embree = 1", ha="left", va="bottom", fontsize=9)
    ax.set_xticks(range(len(kinds)))
    ax.set_xticklabels(kinds, fontsize=10)
    ax.grid(axis="x", visible=False)
    ax.set_ylabel("rays per second, ours / Embree 3 (ratio)")
    ax.set_xlabel("ray kind (one ray at a time unless 'packets'; 1 thread)")
    ax.set_ylim(0, max(1.25, max(float(r["ours_over_embree"]) for r in rows) * 1.15))
    ax.set_title("Grid walk vs Embree 3: rays per second, same rays, timed in turns")
    ax.legend(fontsize=9, loc="upper right")
    ax.grid(axis="y", alpha=0.3)
    if comments:
        fig.text(0.01, 0.01, "one run on a 2-core VM under load, Embree and ours timed in turns: " + comments[0]
                 + "\nbench/trace_plot.py runs build/bench/bench_trace; data: docs/images/trace_vs_embree.csv, .txt",
                 fontsize=7, color="#555555")
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    ps.save(fig, PNG)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--plot-only", action="store_true", help="redraw from docs/images/trace_vs_embree.csv")
    args = parser.parse_args()
    os.makedirs(IMAGES, exist_ok=True)
    if not args.plot_only:
        measure(args)
    plot()


if __name__ == "__main__":
    sys.exit(main())
