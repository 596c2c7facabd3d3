#!/usr/bin/env python3
"""Voxelize time and peak memory against resolution: vox-voxelize (exact) against OpenVDB 10's
meshToUnsignedDistanceField (bench/openvdb_voxelize, as bench/voxelize.sh runs it) and, where it finishes in time,
Open3D 0.16's VoxelGrid.create_from_triangle_mesh, on the 69k Stanford bunny. Keeps the numbers in
docs/images/voxelize_scaling.csv and draws docs/images/voxelize_scaling.png.

Usage: bench/voxelize_plot.py [--build DIR] [--mesh FILE] [--res R ...] [--repeat N] [--threads N]
                              [--open3d-res R ...]                  (measure, then plot; about 3 min of CPU)
       bench/voxelize_plot.py --plot-only                          (plot the stored CSV again)
Needs a build with -DVOX_BENCH=ON, Debian's python3-matplotlib, and python3-open3d for the Open3D points.

Ours and OpenVDB run in turns at each resolution, REPEAT times, the fastest run of each kept, so that load on a
shared machine weighs on both alike: read their ratio. Times are whole processes (read the mesh, voxelize, write the
grid file for ours; read, voxelize for OpenVDB) and voxelization alone; memory is the process's peak resident size.
Open3D runs once per resolution (it tests every voxel against every triangle: a minute at 32^3 on this mesh) and
reports the call alone; it is skipped above --open3d-res.
"""
import argparse
import csv
import datetime
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IMAGES = os.path.join(ROOT, "docs", "images")
CSV = os.path.join(IMAGES, "voxelize_scaling.csv")
PNG = os.path.join(IMAGES, "voxelize_scaling.png")
SEED = os.environ.get("VOX_SEED_DIR", os.path.join(ROOT, "data"))

OPEN3D = r"""
import resource, sys, time
import numpy as np
import open3d as o3d
mesh = o3d.io.read_triangle_mesh(sys.argv[1])
v = np.asarray(mesh.vertices)
size = (v.max(axis=0) - v.min(axis=0)).max() / int(sys.argv[2])
start = time.perf_counter()
grid = o3d.geometry.VoxelGrid.create_from_triangle_mesh(mesh, voxel_size=size)
seconds = time.perf_counter() - start
print(f"voxelize_seconds: {seconds:.6f}")
print(f"occupied_cells: {len(grid.get_voxels())}")
print(f"peak_memory_mb: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.1f}")
"""


def fields(text):
    out = {}
    for line in text.splitlines():
        if ": " in line:
            k, v = line.split(": ", 1)
            out[k.strip()] = v.strip().split()[0] if v.strip() else ""
    return out


def run(cmd, timeout=None):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stderr}")
    return fields(p.stdout + "\n" + p.stderr)


def measure(args):
    vox = os.path.join(args.build, "vox-voxelize")
    vdb = os.path.join(args.build, "bench", "openvdb_voxelize")
    with open("/proc/loadavg") as f:
        load = f.read().split()[0]
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for res in args.res:
            best = {}
            for _ in range(args.repeat):
                for tool, cmd in (("OpenVDB", [vdb, args.mesh, str(res), str(args.threads)]),
                                  ("ours", [vox, args.mesh, "-o", os.path.join(tmp, "g.vgrid"), "--res", str(res),
                                            "--threads", str(args.threads), "--stats", "--quiet"])):
                    f = run(cmd)
                    if tool not in best or float(f["total_seconds"]) < float(best[tool]["total_seconds"]):
                        best[tool] = f
            for tool in ("ours", "OpenVDB"):
                f = best[tool]
                cells = f.get("occupied_cells", f.get("marked_voxels", ""))
                rows.append([res, tool, f["total_seconds"], f["voxelize_seconds"], f["peak_memory_mb"], cells])
                print(f"{res:5} {tool:8} total {float(f['total_seconds']):8.3f} s  voxelize "
                      f"{float(f['voxelize_seconds']):8.3f} s  peak {f['peak_memory_mb']} MB", flush=True)
        for res in args.open3d_res:
            try:
                f = run(["/usr/bin/python3", "-c", OPEN3D, args.mesh, str(res)], timeout=args.open3d_timeout)
            except subprocess.TimeoutExpired:
                print(f"{res:5} Open3D   over {args.open3d_timeout} s, stopped", flush=True)
                break
            rows.append([res, "Open3D", "", f["voxelize_seconds"], f["peak_memory_mb"], f["occupied_cells"]])
            print(f"{res:5} Open3D   voxelize {float(f['voxelize_seconds']):8.3f} s  peak {f['peak_memory_mb']} MB",
                  flush=True)
    seed, path = os.path.realpath(SEED), os.path.realpath(args.mesh)
    mesh = "seed-scenes/" + os.path.relpath(path, seed) if path.startswith(seed + os.sep) else args.mesh
    with open(CSV, "w", newline="") as out:
        out.write(f"# {datetime.date.today()}, commit {commit}, {os.cpu_count()} cores, load average {load} at the "
                  f"start; mesh {mesh}; {args.threads} threads; best of {args.repeat} in turns (Open3D: one run)\n")
        out.write("# python3 bench/voxelize_plot.py --res " + " ".join(map(str, args.res)) + f" --repeat "
                  f"{args.repeat} --threads {args.threads} --open3d-res " + " ".join(map(str, args.open3d_res)) + "\n")
        w = csv.writer(out)
        w.writerow(["res", "tool", "total_s", "voxelize_s", "peak_mb", "cells"])
        w.writerows(rows)
    print(f"wrote {CSV}")


def plot():
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import plot_style as ps

    with open(CSV) as f:
        comments = [line[2:].strip() for line in f if line.startswith("#")]
    with open(CSV) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    series = {}
    for r in rows:
        series.setdefault(r["tool"], []).append(r)
    resolutions = sorted({int(r["res"]) for r in rows})
    fig, (ax_t, ax_m) = ps.figure(5.6, ncols=2)
    style = {"ours": ("o", "#1f77b4", "libvox exact"), "OpenVDB": ("s", "#ff7f0e", "OpenVDB 10"),
             "Open3D": ("^", "#2ca02c", "Open3D 0.16")}
    for tool, pts in series.items():
        marker, colour, label = style.get(tool, ("x", "grey", tool))
        pts = sorted(pts, key=lambda r: int(r["res"]))
        xs = [int(r["res"]) for r in pts]
        ax_t.plot(xs, [float(r["voxelize_s"]) for r in pts], marker=marker, color=colour,
                  label=label + ": voxelization alone (time), peak memory")
        if all(r["total_s"] for r in pts):
            ax_t.plot(xs, [float(r["total_s"]) for r in pts], marker=marker, color=colour, linestyle=":",
                      markerfacecolor="none", label=label + ": whole process (time)")
        ax_m.plot(xs, [float(r["peak_mb"]) for r in pts], marker=marker, color=colour)
    # OpenVDB's whole-process time over ours, same run: the number that load does not bend.
    if "ours" in series and "OpenVDB" in series:
        ours = {int(r["res"]): float(r["total_s"]) for r in series["ours"]}
        for r in series["OpenVDB"]:
            res = int(r["res"])
            if res in ours and res >= 128:
                ax_t.annotate(f"{float(r['total_s']) / ours[res]:.1f}x", (res, float(r["total_s"])),
                              textcoords="offset points", xytext=(0, 7), ha="center", fontsize=8, color="#ff7f0e")
    for ax in (ax_t, ax_m):
        ps.resolution_axis(ax, resolutions)
        ps.log_axis(ax, "y")
        ax.set_xlabel("resolution (cells on the longest axis)")
    ax_t.set_ylabel("time (s)")
    ax_m.set_ylabel("peak resident memory (MB)")
    ax_t.set_title("Time (labels: OpenVDB / ours, whole process)", fontsize=10)
    ax_m.set_title("Peak memory of the process", fontsize=10)
    handles, labels = ax_t.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, bbox_to_anchor=(0.5, 0.065), frameon=False)
    fig.suptitle("Voxelizing the 69k Stanford bunny: libvox (exact) vs OpenVDB 10 and Open3D 0.16", fontsize=11)
    if comments:
        ps.footnote(fig, "one run on a 2-core VM under load: " + comments[0].split("; mesh")[0] + "\n"
                    + comments[1] + "; data: docs/images/voxelize_scaling.csv")
    fig.tight_layout(rect=(0, 0.17, 1, 1))
    ps.save(fig, PNG)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("--mesh", default=os.path.join(SEED, "meshes", "derived", "stanford_bunny_69k.obj"))
    parser.add_argument("--res", type=int, nargs="+", default=[32, 64, 128, 256, 512, 1024, 2048])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--open3d-res", type=int, nargs="*", default=[16, 32])
    parser.add_argument("--open3d-timeout", type=float, default=150)
    parser.add_argument("--plot-only", action="store_true", help="redraw from docs/images/voxelize_scaling.csv")
    args = parser.parse_args()
    os.makedirs(IMAGES, exist_ok=True)
    if not args.plot_only:
        measure(args)
    plot()


if __name__ == "__main__":
    sys.exit(main())
