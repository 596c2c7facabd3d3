"""Shared fixtures of the Python tests (pytest): where the repository, the seed scenes and the tools are, and how to
run a tool and compare two grids cell for cell.

Environment: LIBVOX_TOOLS_DIR (the build folder holding vox-voxelize and friends; default build/ or build-py/ of
the repository), VOX_SEED_DIR (the seed scenes; default what scripts/seed-dir.sh prints).
"""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import libvox

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _seed_dir():
    if os.environ.get("VOX_SEED_DIR"):
        return pathlib.Path(os.environ["VOX_SEED_DIR"])
    out = subprocess.run([str(ROOT / "scripts" / "seed-dir.sh")], capture_output=True, text=True, check=True)
    return pathlib.Path(out.stdout.strip())


def _tools_dir():
    if os.environ.get("LIBVOX_TOOLS_DIR"):
        return pathlib.Path(os.environ["LIBVOX_TOOLS_DIR"])
    for name in ("build", "build-py", "build-python"):
        if (ROOT / name / "vox-voxelize").exists():
            return ROOT / name
    return None


SEED = _seed_dir()
TOOLS = _tools_dir()
SCENES = ROOT / "scenes"
BUNNY_PLY = SEED / "meshes" / "bun_zipper.ply"


@pytest.fixture(scope="session")
def tools():
    if TOOLS is None or not (TOOLS / "vox-voxelize").exists():
        pytest.skip("vox-voxelize not built (set LIBVOX_TOOLS_DIR)")
    return TOOLS


def run_tool(tools, name, *args):
    """Runs a tool; returns its stdout. Fails the test with its stderr when it fails."""
    proc = subprocess.run([str(tools / name), "--quiet", *map(str, args)], capture_output=True, text=True)
    assert proc.returncode == 0, f"{name} {' '.join(map(str, args))}: {proc.stderr}"
    return proc.stdout


def cli_voxelize(tools, tmp_path, scene, *args):
    """vox-voxelize SCENE -o tmp.vgrid ARGS, read back with libvox.load."""
    out = tmp_path / f"cli_{abs(hash((str(scene),) + args))}.vgrid"
    run_tool(tools, "vox-voxelize", scene, "-o", out, *args)
    return out


def info_cells(tools, path):
    """The cells of a grid file as vox-info --json --cells lists them (independent of libvox.load)."""
    info = json.loads(run_tool(tools, "vox-info", path, "--json", "--cells"))
    ijk = np.array([c["ijk"] for c in info["cells"]], dtype=np.int32).reshape(-1, 3)
    prims = [c["prims"] for c in info["cells"]]
    return info, ijk, prims


def box(lo, hi, inward=False):
    """The 12 outward (or inward) triangles of the box [lo, hi] as (vertices, faces)."""
    v = np.array([[hi[0] if c & 1 else lo[0], hi[1] if c & 2 else lo[1], hi[2] if c & 4 else lo[2]]
                  for c in range(8)], dtype=np.float64)
    f = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                  [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]], dtype=np.int64)
    return v, (f[:, ::-1] if inward else f)


def assert_same_grid(a, b):
    """Cell for cell: bounds, dims, method, occupied cells, their primitive ids, solid cells."""
    assert a.dims == b.dims
    assert np.array_equal(a.bounds, b.bounds)
    assert a.method == b.method
    assert a.primitive_count == b.primitive_count
    assert np.array_equal(a.indices, b.indices)
    oa, ia = a.cell_primitives
    ob, ib = b.cell_primitives
    assert np.array_equal(oa, ob)
    assert np.array_equal(ia, ib)
    assert a.solid_count == b.solid_count
    assert np.array_equal(a.solid_indices, b.solid_indices)


def read_ascii_ply(path):
    """Vertices (V, 3) float64 and faces (F, 3) int64 of an ASCII triangle PLY (the Stanford bunny's layout)."""
    with open(path) as f:
        header = []
        for line in f:
            header.append(line.split())
            if line.startswith("end_header"):
                break
        counts = {h[1]: int(h[2]) for h in header if h[0] == "element"}
        rows = [f.readline().split() for _ in range(counts["vertex"])]
        vertices = np.array([[float(x) for x in r[:3]] for r in rows])
        faces = np.array([[int(x) for x in f.readline().split()[1:4]] for _ in range(counts["face"])])
    return vertices, faces
