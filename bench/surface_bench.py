#!/usr/bin/python3
"""The surface back from the field (issue 47) against its two baselines, on the same voxels:

- libvox: `libvox.surface(mesh, resolution=R)`: exact signed distances in a band of 3 cells, then the level set 0 by
  marching tetrahedra (libvox/src/export/level_surface.cpp);
- OpenVDB 10 (pyopenvdb): `FloatGrid.createLevelSetFromPolygons` (meshToLevelSet, half-width 3, voxel centres on
  our cell centres) then `convertToPolygons(isovalue=0, adaptivity=0)` (volumeToMesh), its quads split in two;
- scikit-image's `marching_cubes` (Lewiner) on our dense field `libvox.sdf(mesh, ...)` over the same cells.

Each timed whole, from the mesh's arrays in memory to the surface's arrays, runs alternating, the best of --repeat
kept. Threads: libvox gets threads=--threads; OpenVDB's TBB takes its thread count from the process's CPU affinity,
which this script sets to --threads CPUs before OpenVDB starts (scikit-image's marching cubes is serial; its field,
libvox.sdf, gets --threads). For each output: vertices, triangles, edges with one face (holes' rims), edges with
more than two faces (non-manifold), zero-area triangles, and the Hausdorff distance to the input in cells, sampled
both ways: every output vertex to the input (`Grid.distance` of a grid of the input mesh) and every input vertex to
the output (`Grid.distance` of a grid of the output's triangles). For an open mesh the output closes the holes, so
its vertices on the caps lie far from the input: the mean is given beside the largest.

    PYTHONPATH=build/python python3 bench/surface_bench.py [--repeat 3] [--threads 2] [--res 128 256]

Needs python3-openvdb and python3-skimage (scripts/install-deps.sh --bench).
"""
import argparse
import os
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]


def read_mesh(path):
    """The vertices (as the file holds them, float32 values kept as doubles) and triangles of an OBJ or ASCII PLY."""
    text = pathlib.Path(path).read_text().splitlines()
    if str(path).endswith(".ply"):
        end = text.index("end_header")
        count = {l.split()[1]: int(l.split()[2]) for l in text[:end] if l.startswith("element")}
        rows = text[end + 1:]
        v = np.array([r.split()[:3] for r in rows[:count["vertex"]]], dtype=np.float32).astype(np.float64)
        f = np.array([r.split()[1:4] for r in rows[count["vertex"]:count["vertex"] + count["face"]]], dtype=np.int64)
        return v, f
    v = np.array([l.split()[1:4] for l in text if l.startswith("v ")], dtype=np.float64)
    f = np.array([[int(w.split("/")[0]) - 1 for w in l.split()[1:4]] for l in text if l.startswith("f ")])
    return v, f


def plan(libvox, mesh, res):
    """The cells of libvox.surface(mesh, resolution=res): the scene's cubic cells (as --sdf makes them) with two more
    on every side."""
    g = libvox.voxelize(mesh, resolution=res, sdf=3)
    h = g.pitch[0]
    assert np.all(g.pitch == h), g.pitch
    bounds = g.bounds.copy()
    bounds[0] -= 2 * h
    bounds[1] += 2 * h
    return bounds, tuple(int(d) + 4 for d in g.dims), h


def run_libvox(libvox, mesh, res, threads, bounds, dims, h):
    t = time.perf_counter()
    v, f = libvox.surface(mesh, resolution=res, threads=threads)
    return time.perf_counter() - t, (v, f)


def run_openvdb(vdb, mesh, res, threads, bounds, dims, h):
    t = time.perf_counter()
    points = mesh[0].astype(np.float32)
    triangles = mesh[1].astype(np.int32)
    o = bounds[0] + 0.5 * h  # voxel centres on our cell centres
    xform = vdb.createLinearTransform([[h, 0, 0, 0], [0, h, 0, 0], [0, 0, h, 0], [o[0], o[1], o[2], 1]])
    grid = vdb.FloatGrid.createLevelSetFromPolygons(points, triangles=triangles, transform=xform, halfWidth=3.0)
    v, tris, quads = grid.convertToPolygons(isovalue=0.0, adaptivity=0.0)
    faces = np.concatenate([tris.reshape(-1, 3), quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]]).astype(np.int64)
    seconds = time.perf_counter() - t
    # volumeToMesh's triangles turn clockwise seen from outside; the measures below do not depend on it.
    return seconds, (np.asarray(v, dtype=np.float64), faces)


def run_skimage(libvox, mesh, res, threads, bounds, dims, h):
    from skimage.measure import marching_cubes

    t = time.perf_counter()
    field = libvox.sdf(mesh, dims=dims, bounds=bounds, threads=threads)
    v, f, _, _ = marching_cubes(field, level=0.0, spacing=(h, h, h), method="lewiner")
    seconds = time.perf_counter() - t
    return seconds, (v + bounds[0] + 0.5 * h, f.astype(np.int64))


def edge_defects(faces):
    """(edges with one face, edges with more than two faces) of a triangle mesh, edges unordered."""
    if len(faces) == 0:
        return 0, 0
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e[:, 0].astype(np.int64) << 32 | e[:, 1], return_counts=True)
    return int(np.sum(counts == 1)), int(np.sum(counts > 2))


def zero_area(v, f):
    if len(f) == 0:
        return 0
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    return int(np.sum(np.einsum("ij,ij->i", n, n) == 0))


def hausdorff(libvox, input_grid, mesh, out, threads, h):
    """Largest and mean of: output vertices to the input, input vertices to the output; in cells."""
    v, f = out
    if len(f) == 0:
        return float("inf"), float("inf"), float("inf"), float("inf")
    to_input = input_grid.distance(v, signed=False, threads=threads)[0]
    out_grid = libvox.voxelize((v, f), resolution=64, threads=threads)
    to_output = out_grid.distance(mesh[0], signed=False, threads=threads)[0]
    return to_input.max() / h, to_input.mean() / h, to_output.max() / h, to_output.mean() / h


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--res", type=int, nargs="+", default=[128, 256])
    ap.add_argument("--mesh", type=pathlib.Path, nargs="+",
                    default=[ROOT / "data/6837/scenes/bunny_40k.obj", ROOT / "data/meshes/bun_zipper.ply"])
    args = ap.parse_args()
    # Before OpenVDB's TBB starts: its default thread count is the number of CPUs the process may run on.
    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < args.threads:
        sys.exit("surface_bench.py: --threads %d, but only %d CPUs" % (args.threads, len(cpus)))
    os.sched_setaffinity(0, cpus[:args.threads])
    import pyopenvdb as vdb

    import libvox

    print("| mesh | res | method | seconds | vs OpenVDB | vertices | triangles | boundary edges | non-manifold edges "
          "| zero-area | out->in max / mean (cells) | in->out max / mean (cells) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for path in args.mesh:
        mesh = read_mesh(path)
        input_grid = libvox.voxelize(mesh, resolution=64, threads=args.threads)
        for res in args.res:
            bounds, dims, h = plan(libvox, mesh, res)
            runs = {
                "libvox": lambda: run_libvox(libvox, mesh, res, args.threads, bounds, dims, h),
                "OpenVDB": lambda: run_openvdb(vdb, mesh, res, args.threads, bounds, dims, h),
                "skimage": lambda: run_skimage(libvox, mesh, res, args.threads, bounds, dims, h),
            }
            best = {}
            for _ in range(args.repeat):
                for name, run in runs.items():
                    seconds, out = run()
                    if name not in best or seconds < best[name][0]:
                        best[name] = (seconds, out)
            for name, (seconds, out) in best.items():
                v, f = out
                boundary, nonmanifold = edge_defects(f)
                a, b, c, d = hausdorff(libvox, input_grid, mesh, out, args.threads, h)
                print("| %s | %d | %s | %.3f | %.2fx | %d | %d | %d | %d | %d | %.2f / %.3f | %.2f / %.3f |" % (
                    path.name, res, name, seconds, seconds / best["OpenVDB"][0], len(v), len(f), boundary,
                    nonmanifold, zero_area(v, f), a, b, c, d), flush=True)


if __name__ == "__main__":
    main()
