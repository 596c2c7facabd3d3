"""libvox.Grid pickles (issue 36, item 3b): the state is the grid file's bytes (what Grid.save writes to a .vgrid)
and the grid's source, so pickle.loads(pickle.dumps(grid)) is the same grid cell for cell, primitive for primitive,
with its scene's optional parts (solid cells, spheres and their transforms, planes, cameras, lights, textures, solid
textures, primitives outside user bounds); through every pickle protocol, copy, multiprocessing (spawn) and
concurrent.futures. Corrupt grid bytes in a pickle raise InputError, a state of the wrong type TypeError."""

import concurrent.futures
import copy
import copyreg
import multiprocessing
import pickle

import numpy as np
import pytest

import libvox
import pickle_workers
from conftest import SCENES, SEED, assert_same_grid

TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])

# name -> how to make the grid; together they hold every optional part of a grid file.
GRIDS = {
    "tet_arrays_fill": lambda: libvox.voxelize((TET_V, TET_F), resolution=16, fill=True),
    "bunny_obj": lambda: libvox.voxelize(SCENES / "bunny_1k.obj", resolution=32),
    "spheres_course_fill": lambda: libvox.voxelize(SCENES / "scene5_02_spheres.txt", resolution=24, fill=True),
    "ellipsoid": lambda: libvox.voxelize(SCENES / "scene2_13_rotated_squashed_sphere.txt", resolution=20),
    "sphere_plane": lambda: libvox.voxelize(SCENES / "scene6_03_sphere_plane.txt", resolution=20, method="sat"),
    "textured_gltf": lambda: libvox.voxelize(
        SEED / "gltf" / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf", resolution=12),
    "solid_textures": lambda: libvox.voxelize(SEED / "6837" / "scenes" / "scene6_15_marble_cubes.txt", resolution=16),
    # Half the teapot sticks out of the bounds: its primitives are kept as outside primitives.
    "outside_bounds": lambda: libvox.voxelize(SCENES / "teapot.obj", dims=(12, 10, 8),
                                              bounds=((-1, -1, -1), (0.5, 1, 1)), method="bbox"),
}


def make(name):
    return GRIDS[name]()


def grid_file_bytes(grid, path):
    grid.save(path)
    return path.read_bytes()


def assert_identical(a, b, tmp_path):
    """Everything a Grid shows, and the bytes of its grid file (the whole scene: materials, camera, lights, ...)."""
    assert_same_grid(a, b)
    assert a.source == b.source
    assert repr(a) == repr(b)
    assert np.array_equal(a.dense(), b.dense())
    assert np.array_equal(a.dense(solid=False), b.dense(solid=False))
    assert np.array_equal(a.points, b.points)
    assert np.array_equal(a.counts, b.counts)
    assert np.array_equal(a.transform, b.transform)
    assert np.array_equal(a.colors("material"), b.colors("material"))
    assert grid_file_bytes(a, tmp_path / "a.vgrid") == grid_file_bytes(b, tmp_path / "b.vgrid")
    # The scene's camera, lights and materials in a render; the primitives (outside ones too) in rays.
    assert np.array_equal(libvox.render(a, size=(24, 16), threads=1), libvox.render(b, size=(24, 16), threads=1))
    lo, hi = a.bounds
    rng = np.random.default_rng(7)
    origins = lo + (hi - lo) * rng.uniform(-0.5, 1.5, (64, 3))
    directions = rng.normal(size=(64, 3))
    for x, y in zip(a.intersect(origins, directions), b.intersect(origins, directions)):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("name", GRIDS)
@pytest.mark.parametrize("protocol", range(pickle.HIGHEST_PROTOCOL + 1))
def test_round_trip(tmp_path, name, protocol):
    grid = make(name)
    back = pickle.loads(pickle.dumps(grid, protocol=protocol))
    assert type(back) is libvox.Grid and back is not grid
    assert_identical(grid, back, tmp_path)


def test_round_trip_keeps_optional_parts():
    """The grids above do hold what they are there for (else the round trips would prove less)."""
    assert make("tet_arrays_fill").solid_count > 0
    assert make("spheres_course_fill").solid_count > 0
    assert make("spheres_course_fill").primitive_count == 4  # spheres only, no triangles
    assert len(set(map(tuple, make("textured_gltf").colors("material")))) > 3  # texels, not one colour
    # A ray down onto the teapot's body outside the bounds (x < -1, z > 1) hits it, after a round trip too.
    teapot = make("outside_bounds")
    for grid in (teapot, pickle.loads(pickle.dumps(teapot))):
        t, prim, _ = grid.intersect([[-1.5, 1.5, 10]], [[0, 0, -1]])
        assert prim[0] >= 0 and np.isfinite(t[0])


def test_loaded_grid_and_copies(tmp_path):
    path = tmp_path / "course.vgrid"
    make("spheres_course_fill").save(path)
    grid = libvox.load(path)
    back = pickle.loads(pickle.dumps(grid))
    assert back.source == str(path)
    assert_identical(grid, back, tmp_path)
    assert_identical(grid, copy.copy(grid), tmp_path)
    assert_identical(grid, copy.deepcopy(grid), tmp_path)
    # The state is the grid file as Grid.save writes it, and its source.
    state = grid.__reduce__()[2]
    assert state == (path.read_bytes(), str(path))


def test_comparison_can_fail(tmp_path):
    """assert_identical notices a grid that differs only in its solid cells, or only in its scene."""
    surface = libvox.voxelize((TET_V, TET_F), resolution=16)
    with pytest.raises(AssertionError):
        assert_identical(make("tet_arrays_fill"), surface, tmp_path)
    moved = libvox.voxelize((TET_V, TET_F[[1, 0, 2, 3]]), resolution=16, fill=True)  # same cells, ids swapped
    with pytest.raises(AssertionError):
        assert_identical(make("tet_arrays_fill"), moved, tmp_path)


def test_spawn_pool():
    """multiprocessing's spawn pool: grids made in workers come back; grids sent to workers arrive whole."""
    paths = [SCENES / "bunny_1k.obj", SCENES / "scene5_02_spheres.txt", SCENES / "teapot.obj"]
    fills = [None, True, None]
    sent = [make("tet_arrays_fill"), make("textured_gltf"), make("outside_bounds")]
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        made = pool.starmap(pickle_workers.voxelize, [(p, 24, f) for p, f in zip(paths, fills)])
        seen = pool.map(pickle_workers.describe, sent)
        returned = pool.map(pickle_workers.round_trip, sent)
    for grid, path, fill in zip(made, paths, fills):
        assert_same_grid(grid, libvox.voxelize(path, resolution=24, fill=fill))
        assert np.array_equal(grid.dense(), libvox.voxelize(path, resolution=24, fill=fill).dense())
    for grid, view, back in zip(sent, seen, returned):
        offsets, ids = grid.cell_primitives
        assert np.array_equal(view["dense"], grid.dense())
        assert np.array_equal(view["indices"], grid.indices)
        assert np.array_equal(view["offsets"], offsets) and np.array_equal(view["ids"], ids)
        assert np.array_equal(view["solid"], grid.solid_indices)
        assert np.array_equal(view["bounds"], grid.bounds)
        assert view["state"] == grid.__reduce__()[2]
        assert back.__reduce__()[2] == grid.__reduce__()[2]


@pytest.mark.parametrize("context", ["fork", "spawn"])
def test_process_pool_executor(context):
    paths = [SCENES / "bunny_1k.obj", SCENES / "teapot.obj", SCENES / "scene2_13_rotated_squashed_sphere.txt"]
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context(context)) as pool:
        made = list(pool.map(pickle_workers.voxelize, paths, [20] * 3, [True] * 3))
        returned = list(pool.map(pickle_workers.round_trip, made))
    for grid, back, path in zip(made, returned, paths):
        here = libvox.voxelize(path, resolution=20, fill=True)
        assert_same_grid(grid, here)
        assert_same_grid(back, here)
        assert np.array_equal(back.dense(), here.dense())
        assert back.__reduce__()[2][0] == here.__reduce__()[2][0]


class Forged:
    """Pickles as a Grid with the given state: what a corrupted pickle of a Grid unpickles as."""

    def __init__(self, state):
        self.state = state

    def __reduce__(self):
        return copyreg.__newobj__, (libvox.Grid,), self.state


def loads_forged(state):
    return pickle.loads(pickle.dumps(Forged(state), protocol=1))  # 2 and up check the class of the object


def test_forged_pickle_of_the_real_state_loads(tmp_path):
    grid = make("spheres_course_fill")
    assert_identical(grid, loads_forged(grid.__reduce__()[2]), tmp_path)


def test_truncated_grid_bytes_raise_input_error():
    data, source = make("tet_arrays_fill").__reduce__()[2]
    for n in range(len(data)):
        with pytest.raises(libvox.InputError, match="pickled grid"):
            loads_forged((data[:n], source))
    with pytest.raises(libvox.InputError):
        loads_forged((data + b"\0", source))


def test_flipped_bytes_raise_input_error():
    """Every byte of the grid file inside a real pickle, flipped: InputError each time (the checksum and the header's
    checks), never a crash or a different grid."""
    grid = make("tet_arrays_fill")
    data = grid.__reduce__()[2][0]
    pickled = pickle.dumps(grid)
    at = pickled.find(data)
    assert at > 0
    for i in range(at, at + len(data)):
        for mask in (0x01, 0x80):
            corrupt = bytearray(pickled)
            corrupt[i] ^= mask
            with pytest.raises(libvox.InputError):
                pickle.loads(bytes(corrupt))


def test_newer_version_raises_input_error():
    data, source = make("tet_arrays_fill").__reduce__()[2]
    version = data.find((3).to_bytes(4, "little"))
    assert 0 < version < 32
    newer = data[:version] + (99).to_bytes(4, "little") + data[version + 4:]
    with pytest.raises(libvox.InputError, match="version"):
        loads_forged((newer, source))


def test_not_a_grid_file_raises_input_error():
    for junk in (b"", b"hello", b"\0" * 64, pickle.dumps(make("tet_arrays_fill"))):
        with pytest.raises(libvox.InputError):
            loads_forged((junk, "<arrays>"))


@pytest.mark.parametrize("state", [int, 42, "text", b"bytes", (), ("text", "src"), (b"x",),
                                   (b"x", b"src"), (b"x", "src", 1), [b"x", "src"], {"bytes": b"x"}],
                         ids=repr)
def test_state_of_the_wrong_type_raises_type_error(state):
    grid = make("tet_arrays_fill")
    if isinstance(state, tuple) and len(state) == 2 and state[0] == b"x":
        state = (grid.__reduce__()[2][0], state[1])  # good bytes, a bad source
    with pytest.raises(TypeError, match="__setstate__"):
        loads_forged(state)
