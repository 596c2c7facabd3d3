#!/usr/bin/python3
"""The Python package against C++ and against Open3D, ratios measured in one run (docs/python.md "Speed").

    /usr/bin/python3 bench/python_bench.py [--quick]     # with libvox importable (installed, or PYTHONPATH=BUILD/python)

1. Python overhead: 1,000 small meshes at 32^3 (one voxelize call each) and the Stanford bunny at 1024^3, against
   the same voxelizeScene calls in a C++ loop (libvox._voxelize_loop); best of three runs each.
2. voxelize_batch of 1,000 meshes at 64^3: 2 threads against 1.
3. Open3D 0.16 (Debian's python3-open3d): VoxelGrid.create_from_triangle_mesh on the bunny at 32, 64, 128; its grid
   starts half a voxel below the mesh's minimum (min_bound - voxel_size / 2), so libvox voxelizes over that same
   lattice (bounds = Open3D's origin + n * voxel_size) and the cells are compared index for index.
4. Rays: Grid.intersect against Open3D's RaycastingScene.cast_rays, where Open3D's build answers correctly.
"""

import argparse
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import libvox
import libvox._libvox

ROOT = pathlib.Path(__file__).resolve().parents[1]


def seed_dir():
    if os.environ.get("VOX_SEED_DIR"):
        return pathlib.Path(os.environ["VOX_SEED_DIR"])
    out = subprocess.run([str(ROOT / "scripts" / "seed-dir.sh")], capture_output=True, text=True, check=True)
    return pathlib.Path(out.stdout.strip())


def read_ascii_ply(path):
    with open(path) as f:
        header = []
        for line in f:
            header.append(line.split())
            if line.startswith("end_header"):
                break
        counts = {h[1]: int(h[2]) for h in header if h[0] == "element"}
        vertices = np.array([[float(x) for x in f.readline().split()[:3]] for _ in range(counts["vertex"])])
        faces = np.array([[int(x) for x in f.readline().split()[1:4]] for _ in range(counts["face"])])
    return vertices, faces


def read_obj(path):
    """Vertices and triangles of an OBJ of plain `v x y z` and `f a b c` lines."""
    v, f = [], []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            v.append([float(x) for x in p[1:4]])
        elif p and p[0] == "f":
            f.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
    return np.array(v), np.array(f)


def small_meshes(count, seed=1):
    """Closed random tetrahedra (4 triangles each), as learning pipelines voxelize small parts."""
    rng = np.random.default_rng(seed)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return [(rng.normal(size=(4, 3)) * rng.uniform(0.5, 2, size=3) + rng.uniform(-5, 5, size=3), faces)
            for _ in range(count)]


def best_of(n, fn):
    best = float("inf")
    for _ in range(n):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def timed(fn):
    """Wall and CPU seconds (all the process's threads) of fn()."""
    cpu, wall = time.process_time(), time.perf_counter()
    fn()
    return time.perf_counter() - wall, time.process_time() - cpu


def overhead(meshes, bunny, runs, bunny_res):
    print("== Python overhead: the calls against the same voxelizeScene calls in a C++ loop (libvox._voxelize_loop), "
          "one thread each, runs alternating, the best of %d; wall time, and CPU time (what other jobs on the machine "
          "change least)" % runs)
    for label, sources, res in [("%d meshes at 32^3" % len(meshes), meshes, 32),
                                ("bunny (69,451 triangles) at %d^3" % bunny_res, [bunny], bunny_res)]:
        def python_calls():
            for s in sources:
                libvox.voxelize(s, resolution=res, threads=1)

        def cpp_loop():
            libvox._libvox._voxelize_loop(sources, res, threads=1)

        best = {"cpp": [float("inf")] * 2, "py": [float("inf")] * 2}
        for _ in range(runs):  # alternating, so that other jobs on the machine weigh on both alike
            for name, fn in (("cpp", cpp_loop), ("py", python_calls)):
                best[name] = [min(a, b) for a, b in zip(best[name], timed(fn))]
        (cw, cc), (pw, pc) = best["cpp"], best["py"]
        print(f"{label}: wall C++ {cw:.4f} s, Python {pw:.4f} s, ratio {pw / cw:.3f}; CPU C++ {cc:.4f} s, Python "
              f"{pc:.4f} s, ratio {pc / cc:.3f}", flush=True)


def batch_scaling(meshes, runs):
    print("== voxelize_batch of %d meshes at 64^3 (best of %d)" % (len(meshes), runs))
    t = {n: best_of(runs, lambda: libvox.voxelize_batch(meshes, 64, threads=n)) for n in (1, 2)}
    print(f"1 thread {t[1]:.3f} s, 2 threads {t[2]:.3f} s, speed-up {t[1] / t[2]:.2f}x (cores: {os.cpu_count()})", flush=True)


def open3d_voxels(o3d, name, vertices, faces, resolutions):
    print("== Open3D %s VoxelGrid.create_from_triangle_mesh vs libvox (exact) on the same lattice: %s (%d triangles)"
          % (o3d.__version__, name, len(faces)), flush=True)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(vertices), o3d.utility.Vector3iVector(faces))
    extent = (vertices.max(axis=0) - vertices.min(axis=0)).max()
    for r in resolutions:
        size = extent / r
        start = time.perf_counter()
        vg = o3d.geometry.VoxelGrid.create_from_triangle_mesh(mesh, voxel_size=size)
        t_o3d = time.perf_counter() - start
        theirs = np.array([v.grid_index for v in vg.get_voxels()], dtype=np.int64)
        # Open3D's voxel (i, j, k) is the box of side voxel_size centred on origin + (i, j, k) * voxel_size (origin =
        # the mesh's minimum - voxel_size / 2): undone, libvox's cell (i, j, k) of a lattice starting half a voxel
        # lower is the same box. One more cell a side than Open3D uses keeps every libvox cell in the lattice.
        origin = np.asarray(vg.origin) - size / 2
        dims = theirs.max(axis=0) + 2
        start = time.perf_counter()
        g = libvox.voxelize((vertices, faces), dims=tuple(int(d) for d in dims),
                            bounds=(origin, origin + dims * size))
        t_vox = time.perf_counter() - start
        ours = g.indices.astype(np.int64)
        a = {tuple(c) for c in theirs}
        b = {tuple(c) for c in ours}
        print(f"{r}^3 (voxel {size:.6g}): Open3D {t_o3d:.4f} s, {len(a)} cells; "
              f"libvox {t_vox:.4f} s, {len(b)} cells; shared {len(a & b)}, only Open3D {len(a - b)}, only libvox "
              f"{len(b - a)}; libvox / Open3D time {t_vox / t_o3d:.4f}", flush=True)


def rays(o3d, vertices, faces, count, runs):
    print("== Rays: %d rays from around the bunny towards it" % count)
    grid = libvox.voxelize((vertices, faces))
    rng = np.random.default_rng(5)
    lo, hi = grid.bounds
    origins = lo + (hi - lo) * (rng.random((count, 3)) * 3 - 1)
    directions = lo + (hi - lo) * rng.random((count, 3)) - origins
    grid.intersect(origins[:1000], directions[:1000])  # builds the trace structure, not timed
    t_vox = best_of(runs, lambda: grid.intersect(origins, directions))
    t, prim, _ = grid.intersect(origins, directions)
    print(f"libvox intersect: {count / t_vox:.3g} rays/s ({(prim >= 0).mean():.1%} hit)")
    if o3d is None:
        return
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)), o3d.core.Tensor(faces.astype(np.uint32)))
    r = o3d.core.Tensor(np.hstack([origins, directions]).astype(np.float32))
    t_o3d = best_of(runs, lambda: scene.cast_rays(r))
    hits = scene.cast_rays(r)["t_hit"].numpy()
    agree = np.mean(np.isfinite(hits) == (prim >= 0))
    if np.isfinite(hits).sum() == 0 and (prim >= 0).sum() > 0:
        print(f"Open3D cast_rays: {count / t_o3d:.3g} rays/s but it reports no hit at all ({(prim >= 0).sum()} rays "
              "hit the mesh): Debian's build does not work; no ratio")
    else:
        print(f"Open3D cast_rays (float32): {count / t_o3d:.3g} rays/s; hit/miss agrees on {agree:.2%} of rays; "
              f"libvox / Open3D rays per second {t_o3d / t_vox:.2f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer meshes and runs, bunny at 256^3 (a smoke test)")
    args = parser.parse_args()
    runs = 1 if args.quick else 5
    print(f"libvox {libvox.__version__}, Python {sys.version.split()[0]}, numpy {np.__version__}, "
          f"{os.cpu_count()} cores")
    vertices, faces = read_ascii_ply(seed_dir() / "meshes" / "bun_zipper.ply")
    meshes = small_meshes(100 if args.quick else 1000)
    overhead(meshes, (vertices, faces), runs, 256 if args.quick else 1024)
    batch_scaling(meshes, runs)
    try:
        import open3d as o3d
    except ImportError:
        o3d = None
        print("== Open3D not installed (Debian: python3-open3d); its comparisons skipped")
    if o3d is not None:
        # Open3D 0.16 tests every triangle against every voxel of the grid (time grows as R^3 x triangles): the
        # 1,000-triangle bunny at every resolution, the full bunny at 32^3 only (minutes beyond).
        bunny_1k = read_obj(ROOT / "scenes" / "bunny_1k.obj")
        open3d_voxels(o3d, "bunny_1k.obj", *bunny_1k, [32, 64] if args.quick else [32, 64, 128])
        if not args.quick:
            open3d_voxels(o3d, "bun_zipper.ply", vertices, faces, [32])
    rays(o3d, vertices, faces, 100_000 if args.quick else 1_000_000, runs)


if __name__ == "__main__":
    main()
