#!/usr/bin/python3
"""Distances from Python against Open3D (issue 38), ratios measured in one run, runs alternating, best of --repeat:

1. Grid.distance(points, signed=False) on 1,000,000 points uniform in the Stanford bunny's bounding box against
   Open3D 0.16's RaycastingScene.compute_distance (Debian's python3-open3d; its signed call answers only positive
   values in that build, so the unsigned one is compared), and the largest difference of the two distances;
2. the signed call, for its cost;
3. libvox.sdf of the bunny, dense, at 64^3 and 128^3.

    python bench/distance_bench.py [--repeat N] [--points P] [--threads T] [--cpu-time]   # with libvox importable

--cpu-time times each call by the process's CPU time over all its threads (time.process_time) instead of the wall
clock: on a machine other jobs load, the work each side does, not the share of the cores it was given.
"""
import argparse
import os
import pathlib
import time

import numpy as np

import libvox

ROOT = pathlib.Path(__file__).resolve().parents[1]


clock = time.perf_counter


def best(repeat, fn):
    times, out = [], None
    for _ in range(repeat):
        t = clock()
        out = fn()
        times.append(clock() - t)
    return min(times), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--cpu-time", action="store_true")
    args = ap.parse_args()
    global clock
    if args.cpu_time:
        clock = time.process_time
    seed = pathlib.Path(os.environ.get("VOX_SEED_DIR", ROOT / "data"))
    bunny = str(seed / "meshes" / "bun_zipper.ply")
    grid = libvox.voxelize(bunny, resolution=64, threads=args.threads)
    lo, hi = np.array(grid.bounds[0]), np.array(grid.bounds[1])
    points = np.random.default_rng(1).uniform(lo, hi, size=(args.points, 3))
    print(f"bunny: {grid.primitive_count} triangles, {args.points} points, {args.threads} threads, best of {args.repeat}")
    try:
        import open3d as o3d
    except ImportError:
        o3d = None
        print("Open3D not installed (Debian: python3-open3d): its comparison skipped")
    ours_s, theirs_s = [], []
    ours = theirs = None
    scene = None
    if o3d is not None:
        mesh = o3d.io.read_triangle_mesh(bunny)
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
        query = o3d.core.Tensor(points.astype(np.float32))
    for _ in range(args.repeat):  # alternating
        t = clock()
        ours = grid.distance(points, signed=False, threads=args.threads)[0]
        ours_s.append(clock() - t)
        if scene is not None:
            t = clock()
            theirs = scene.compute_distance(query, nthreads=args.threads).numpy()
            theirs_s.append(clock() - t)
    print(f"Grid.distance (unsigned): {min(ours_s):.3f} s, {args.points / min(ours_s):,.0f} points/s")
    if theirs is not None:
        print(f"Open3D compute_distance:  {min(theirs_s):.3f} s, {args.points / min(theirs_s):,.0f} points/s")
        print(f"libvox / Open3D points per second: {min(theirs_s) / min(ours_s):.2f}")
        diff = np.abs(ours - theirs.astype(np.float64))
        print(f"largest difference: {diff.max():.3g} ({diff.max() / np.abs(ours).max():.3g} of the largest distance)")
    s, _ = best(args.repeat, lambda: grid.distance(points, signed=True, threads=args.threads))
    print(f"Grid.distance (signed):   {s:.3f} s, {args.points / s:,.0f} points/s")
    for res in (64, 128):
        s, field = best(args.repeat, lambda: libvox.sdf(bunny, resolution=res, threads=args.threads))
        print(f"libvox.sdf {res}: {s:.3f} s, shape {field.shape}, {field.size / s:,.0f} cells/s")


if __name__ == "__main__":
    main()
