"""A folder of meshes voxelized on a Dask cluster of two worker processes (issue 36, item 4; docs/python.md "Many
meshes over processes and machines"): the arrays and the Grids gathered from the workers equal
libvox.voxelize_batch's in this process, bit for bit and cell for cell."""

import os
import shutil

import numpy as np
import pytest

import libvox
from conftest import SCENES, SEED, assert_same_grid

distributed = pytest.importorskip("distributed")
# Debian 12's tornado and distributed 2022.12 warn about each other, not about libvox.
pytestmark = pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")

RES = 32
# OBJ, PLY (the 69k-triangle Stanford bunny, ASCII) and binary glTF, from 12 to 69,451 triangles.
MESHES = [
    SCENES / "bunny_1k.obj",
    SCENES / "cube.obj",
    SCENES / "teapot.obj",
    SEED / "meshes" / "spot.obj",
    SEED / "meshes" / "bun_zipper.ply",
    SEED / "gltf" / "Duck" / "glTF-Binary" / "Duck.glb",
]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The meshes copied into a folder of their own, as a user's data set would be."""
    out = tmp_path_factory.mktemp("meshes")
    for m in MESHES:
        shutil.copy(m, out / m.name)
    return out


@pytest.fixture(scope="module")
def paths(folder):
    return sorted(str(p) for p in folder.iterdir())


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as c:
        yield c


def voxelize_chunk(chunk, fill):
    """A task: its meshes' dense cubes, with the worker's process id (to show where it ran)."""
    return os.getpid(), libvox.voxelize_batch(chunk, RES, fill=fill, threads=1)


@pytest.mark.parametrize("fill", [None, True], ids=["surface", "fill"])
def test_dense_arrays_equal_voxelize_batch(client, paths, fill):
    chunks = [paths[i:i + 2] for i in range(0, len(paths), 2)]
    results = client.gather(client.map(lambda chunk: voxelize_chunk(chunk, fill), chunks))
    pids = {pid for pid, _ in results}
    assert os.getpid() not in pids  # the work ran in the worker processes
    gathered = np.concatenate([arrays for _, arrays in results])
    here = libvox.voxelize_batch(paths, RES, fill=fill)
    assert gathered.dtype == here.dtype == np.bool_
    assert gathered.shape == here.shape == (len(paths), RES, RES, RES)
    assert np.array_equal(gathered, here)
    assert gathered.tobytes() == here.tobytes()
    assert here.any(axis=(1, 2, 3)).all()  # every mesh has cells (else equality would prove little)


def test_grids_gathered_equal_voxelize_batch(client, paths):
    """Grids made on the workers come back through pickle (their grid file's bytes) whole."""
    futures = client.map(lambda path: libvox.voxelize_batch([path], RES, fill=True, dense=False)[0], paths)
    gathered = client.gather(futures)
    here = libvox.voxelize_batch(paths, RES, fill=True, dense=False)
    assert len(gathered) == len(here) == len(paths)
    for a, b in zip(gathered, here):
        assert isinstance(a, libvox.Grid)
        assert_same_grid(a, b)
        assert a.source == b.source
        assert np.array_equal(a.dense(), b.dense())
        assert a.__getstate__() == b.__getstate__()  # the same grid file bytes
    assert np.array_equal(np.stack([g.dense() for g in gathered]), libvox.voxelize_batch(paths, RES, fill=True))


def test_grids_sent_to_workers(client, paths):
    """Grids scattered to the workers arrive whole: the workers' rays and arrays are this process's."""
    grids = libvox.voxelize_batch(paths, RES, dense=False)
    remote = client.scatter(grids)
    origins = np.array([[0.0, 0.0, 0.0], [0.1, 0.2, 0.3]])
    directions = np.array([[1.0, 0.3, 0.2], [-0.2, 1.0, 0.1]])
    dense = client.gather(client.map(lambda g: g.dense(), remote))
    hits = client.gather(client.map(lambda g: g.intersect(origins, directions, threads=1), remote))
    for grid, d, h in zip(grids, dense, hits):
        assert np.array_equal(d, grid.dense())
        for x, y in zip(h, grid.intersect(origins, directions, threads=1)):
            assert np.array_equal(x, y)
