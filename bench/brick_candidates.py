"""How long a brick's shared candidate list would be (issue 46, "the dense field by bricks").

A brick of B^3 cells could share one list of candidate triangles: those whose distance to the brick's box of cell
centres is at most the brick's upper bound U = d0 + r (d0: the exact distance from the brick's middle cell centre c,
r: the farthest centre's distance from c). That list lies between two sets this script counts exactly for random
bricks of the 69k bunny's 128^3 field (numpy, every triangle's distance to c in double):
  - at least the triangles within U = d0 + r of c (c lies in the box, so they pass), and
  - at most the triangles within U + r = d0 + 2r of c (a triangle farther than that from c is farther than U from
    every point of the box).
    PYTHONPATH=build/python python3 bench/brick_candidates.py [--bricks 200] [--res 128] [MESH]
"""
import argparse
import pathlib

import numpy as np

import libvox
from fields import read_ascii_ply


def point_triangle_distances(p, a, b, c):
    """The distance from point p to each triangle (a[i], b[i], c[i]): Ericson's regions, vectorized."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v, w = vb / denom, vc / denom
        q = a + ab * v[:, None] + ac * w[:, None]  # inside the face
        t_ab = np.clip(d1 / (d1 - d3), 0, 1)
        t_ac = np.clip(d2 / (d2 - d6), 0, 1)
        t_bc = np.clip((d4 - d3) / ((d4 - d3) + (d5 - d6)), 0, 1)
    q = np.where(((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0))[:, None], b + (c - b) * t_bc[:, None], q)
    q = np.where(((vb <= 0) & (d2 >= 0) & (d6 <= 0))[:, None], a + ac * t_ac[:, None], q)
    q = np.where(((vc <= 0) & (d1 >= 0) & (d3 <= 0))[:, None], a + ab * t_ab[:, None], q)
    q = np.where(((d6 >= 0) & (d5 <= d6))[:, None], c, q)
    q = np.where(((d3 >= 0) & (d4 <= d3))[:, None], b, q)
    q = np.where(((d1 <= 0) & (d2 <= 0))[:, None], a, q)
    q = np.where(np.isfinite(q), q, a)  # degenerate triangles: their first corner (counts only)
    return np.linalg.norm(p - q, axis=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mesh", nargs="?", default=str(pathlib.Path(__file__).parent.parent / "data/meshes/bun_zipper.ply"))
    parser.add_argument("--bricks", type=int, default=200)
    parser.add_argument("--res", type=int, default=128)
    args = parser.parse_args()
    grid = libvox.voxelize(args.mesh, resolution=args.res)
    vertices, faces = read_ascii_ply(args.mesh)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    lo, dims = np.array(grid.bounds[0]), np.array(grid.dims)
    h = (np.array(grid.bounds[1]) - lo) / dims
    rng = np.random.default_rng(1)
    print(f"{args.mesh}: {len(faces)} triangles, {args.res} ({dims[0]} x {dims[1]} x {dims[2]}), "
          f"{args.bricks} random bricks each")
    print("| brick | candidates, middle cell 8+ cells from the surface | candidates, nearer |")
    print("|---|---|---|")
    for size in (2, 4, 8):
        rows = {True: [], False: []}
        for _ in range(args.bricks):
            first = rng.integers(0, np.maximum(dims // size, 1)) * size
            middle = lo + (first + (size - 1) // 2 + 0.5) * h
            r = np.linalg.norm(h * np.maximum(size - 1 - (size - 1) // 2, (size - 1) // 2))
            d = point_triangle_distances(middle, a, b, c)
            d0 = d.min()
            rows[bool(d0 >= 8 * h.min())].append(((d <= d0 + r).sum(), (d <= d0 + 2 * r).sum()))
        cells = []
        for far in (True, False):
            counts = np.array(rows[far]) if rows[far] else np.zeros((1, 2))
            cells.append(f"{np.median(counts[:, 0]):.0f}-{np.median(counts[:, 1]):.0f} triangles "
                         f"(median of {len(rows[far])})")
        print(f"| {size}^3 | {cells[0]} | {cells[1]} |")


if __name__ == "__main__":
    main()
