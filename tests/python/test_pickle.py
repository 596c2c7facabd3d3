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
import subprocess
import sys
import textwrap

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
    state = grid.__getstate__()
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
        assert view["state"] == grid.__getstate__()
        assert back.__getstate__() == grid.__getstate__()


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
        assert back.__getstate__()[0] == here.__getstate__()[0]


class Forged:
    """Pickles as a Grid with the given state: what a corrupted pickle of a Grid unpickles as."""

    def __init__(self, state):
        self.state = state

    def __reduce__(self):
        return libvox._unpickle_grid, (self.state,)


def loads_forged(state):
    return pickle.loads(pickle.dumps(Forged(state)))


def test_forged_pickle_of_the_real_state_loads(tmp_path):
    grid = make("spheres_course_fill")
    assert_identical(grid, loads_forged(grid.__getstate__()), tmp_path)


def test_truncated_grid_bytes_raise_input_error():
    data, source = make("tet_arrays_fill").__getstate__()
    for n in range(len(data)):
        with pytest.raises(libvox.InputError, match="pickled grid"):
            loads_forged((data[:n], source))
    with pytest.raises(libvox.InputError):
        loads_forged((data + b"\0", source))


def test_flipped_bytes_raise_input_error():
    """Every byte of the grid file inside a real pickle, flipped: InputError each time (the checksum and the header's
    checks), never a crash or a different grid."""
    grid = make("tet_arrays_fill")
    data = grid.__getstate__()[0]
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
    data, source = make("tet_arrays_fill").__getstate__()
    version = data.find((3).to_bytes(4, "little"))
    assert 0 < version < 32
    newer = data[:version] + (99).to_bytes(4, "little") + data[version + 4:]
    with pytest.raises(libvox.InputError, match="version"):
        loads_forged((newer, source))


def test_not_a_grid_file_raises_input_error():
    for junk in (b"", b"hello", b"\0" * 64, pickle.dumps(make("tet_arrays_fill"))):
        with pytest.raises(libvox.InputError):
            loads_forged((junk, "<arrays>"))


# Issue 45: each message says what is wrong with the state (it said "must be a tuple ..., got tuple").
@pytest.mark.parametrize("state,message", [
    (int, "not type"), (42, "not int"), ("text", "not str"), (b"bytes", "not bytes"), ([b"x", "src"], "not list"),
    ({"bytes": b"x"}, "not dict"), (None, "not NoneType"),
    ((), "got a tuple of 0 items"), ((b"x",), "got a tuple of 1 items"), ((b"x", "src", 1), "got a tuple of 3 items"),
    (("text", "src"), "its first item is str, not bytes"), ((b"x", b"src"), "its second item is bytes, not str"),
], ids=repr)
def test_state_of_the_wrong_type_raises_type_error(state, message):
    grid = make("tet_arrays_fill")
    if isinstance(state, tuple) and len(state) == 2 and state[0] == b"x":
        state = (grid.__getstate__()[0], state[1])  # good bytes, a bad source
    with pytest.raises(TypeError, match=r"^pickled libvox.Grid: the state must be \(grid file bytes, source str\)[,:] "
                                        + message + "$"):
        loads_forged(state)


def test_old_style_pickles_raise_type_error():
    """Grid.__new__ refuses (issue 45): the stream of copyreg.__newobj__(Grid) with or without a state (what
    libvox wrote before, and the 25-byte stream that gave a Grid without its grid) raises TypeError."""
    class OldStyle:
        def __init__(self, *state):
            self.state = state

        def __reduce__(self):
            return (copyreg.__newobj__, (libvox.Grid,)) + self.state

    # Protocols 0 and 1 through copyreg.__newobj__; 2 and up with the NEWOBJ opcode (pickle.dumps would check the
    # class, so the stream is written here: PROTO, GLOBAL libvox._libvox Grid, EMPTY_TUPLE, NEWOBJ, STOP).
    streams = [pickle.dumps(OldStyle(*state), protocol=protocol) for protocol in (0, 1)
               for state in ((), (make("tet_arrays_fill").__getstate__(),))]
    streams += [b"\x80" + bytes([protocol]) + b"clibvox._libvox\nGrid\n)\x81." for protocol in range(2, 6)]
    assert len(streams[-1]) < 30
    for stream in streams:
        with pytest.raises(TypeError, match="libvox.Grid cannot be made directly"):
            pickle.loads(stream)
    with pytest.raises(TypeError, match="libvox.Grid cannot be made directly"):
        libvox.Grid.__new__(libvox.Grid)
    with pytest.raises(TypeError, match="libvox.Grid cannot be made directly"):
        libvox.Grid()


def test_setstate_of_a_live_grid_raises_and_changes_nothing():
    """Issue 45, defect 14: __setstate__ on a live Grid did nothing and raised nothing."""
    grid, other = make("tet_arrays_fill"), make("bunny_obj")
    before = grid.__getstate__()
    for state in (other.__getstate__(), before, 42):
        with pytest.raises(TypeError, match="already initialised"):
            grid.__setstate__(state)
        assert grid.__getstate__() == before


def run_child(script, *args):
    """A child interpreter: a crash there fails the test instead of ending pytest."""
    return subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True,
                          timeout=600)


# Issue 45, defect 3: a Grid object without its C++ grid (pybind11's base __new__ still makes one, bypassing
# Grid.__new__) raises TypeError from every attribute and method, repr and pickle included, instead of reading
# uninitialised memory.
BARE = textwrap.dedent("""
    import pickle, sys
    import libvox
    bare = libvox.Grid.__mro__[1].__new__(libvox.Grid)
    ray = [[0.5, 0.5, -1]], [[0, 0, 1]]
    ARGS = {"save": ("x.vgrid",), "contains": ([[0, 0, 0]],), "distance": ([[0, 0, 0]],), "intersect": ray,
            "occluded": ray, "__setstate__": (None,)}
    calls = {"repr": lambda: repr(bare), "pickle": lambda: pickle.dumps(bare), "str": lambda: str(bare),
             "render": lambda: libvox.render(bare)}
    for name in dir(libvox.Grid):
        if name.startswith("__") and name not in ("__getstate__", "__setstate__", "__reduce__", "__repr__"):
            continue
        member = getattr(libvox.Grid, name)
        if isinstance(member, property):
            calls[name] = (lambda n: lambda: getattr(bare, n))(name)
        else:
            args = ARGS.get(name, ())
            calls[name] = (lambda m, a: lambda: m(bare, *a))(member, args)
    for name, call in calls.items():
        try:
            call()
            print(name, "returned")
        except TypeError as e:
            print(name, "TypeError", "holds no grid" in str(e))
    print("alive")
""")


def test_grid_without_its_grid_raises_type_error():
    proc = run_child(BARE)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}{proc.stderr}"
    lines = proc.stdout.splitlines()
    assert lines[-1] == "alive"
    assert len(lines) > 25, proc.stdout  # every property and method was tried
    assert all(line.endswith("TypeError True") for line in lines[:-1]), proc.stdout


# Mutated and truncated pickles of a small grid, all in one child (which would end on a crash): each one loads as
# the same grid, or raises an exception of the documented kinds (ValueError and its subclasses InputError and
# UsageError, TypeError, UnpicklingError) or one of pickle's own about the stream (EOFError for a truncation, a
# name that does not resolve, a memo or stack error); never a different Grid, never a crash.
FUZZ = textwrap.dedent("""
    import collections, pickle, random, resource, sys
    import numpy as np
    import libvox
    # A mutated memo index or length makes pickle itself allocate and clear gigabytes (seconds a stream): a limit
    # on the address space turns that into a quick MemoryError.
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    grid = libvox.voxelize((V, F), resolution=3, fill=True)
    state = grid.__getstate__()
    # pickle's own about a broken stream: EOFError (cut short), ImportError and AttributeError (a name that does not
    # resolve), LookupError (a memo key, the codec name of protocols 0 to 2), OverflowError, MemoryError, RecursionError.
    ALLOWED = (ValueError, TypeError, pickle.UnpicklingError, EOFError, ImportError, AttributeError, LookupError,
               MemoryError, OverflowError, RecursionError)
    rng = random.Random(int(sys.argv[1]))
    outcomes = collections.Counter()

    def grids_in(obj, depth=0):
        if isinstance(obj, libvox.Grid):
            yield obj
        elif isinstance(obj, (tuple, list, set, frozenset)) and depth < 5:
            for item in obj:
                yield from grids_in(item, depth + 1)
        elif isinstance(obj, dict) and depth < 5:
            for item in obj.items():
                yield from grids_in(item, depth + 1)

    def mutated(stream):
        data = bytearray(stream)
        for _ in range(rng.choice((1, 1, 2, 3, 8))):
            kind, at = rng.randrange(4), rng.randrange(len(data))
            if kind == 0:
                data[at] = rng.randrange(256)
            elif kind == 1:
                data[at] ^= 1 << rng.randrange(8)
            elif kind == 2:
                del data[at:at + rng.randrange(1, 16)]
            else:
                data[at:at] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 8)))
        return bytes(data)

    streams = []
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        stream = pickle.dumps(grid, protocol=protocol)
        streams += [stream[:n] for n in range(len(stream))]
        streams += [mutated(stream) for _ in range(int(sys.argv[2]))]
    for stream in streams:
        try:
            loaded = pickle.loads(stream)
        except ALLOWED as e:
            outcomes[type(e).__name__] += 1
            continue
        except Exception as e:
            print("unexpected", type(e).__name__, e, stream)
            continue
        for g in grids_in(loaded):
            if g.__getstate__()[0] != state[0]:  # the grid; its source is a name the stream may spell otherwise
                print("a different grid from", stream)
            outcomes["equal grid"] += 1
        outcomes["loaded"] += 1
    print(len(streams), dict(outcomes))
""")


def test_fuzzed_pickles_load_equal_or_raise():
    proc = run_child(FUZZ, 45, 2000)
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
    assert "a different grid" not in proc.stdout and "unexpected" not in proc.stdout, proc.stdout[-2000:]
    count, outcomes = proc.stdout.split(" ", 1)
    assert int(count) > 2000
    assert "equal grid" in outcomes and "InputError" in outcomes, outcomes  # both kinds were reached
