"""The package at its edges (issue 37): each of the ten defects found by probing it as a hostile user would, with
the inputs of the report, and one catalogue of wrong values fed to every public function and keyword. A wrong
argument raises TypeError, InputError or UsageError (ValueErrors), LimitError (a MemoryError) or OSError, and its
message names the argument; nothing is cut or rounded silently, and no byte of an input raises UnicodeDecodeError."""

import os
import pathlib
import warnings

import numpy as np
import pytest

import libvox

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
TRI_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


@pytest.fixture
def grid():
    return libvox.voxelize((V, F), resolution=4)


# 1. A NUL in a path is refused (ValueError, as open() refuses it), not cut.
def test_nul_in_path_refused(tmp_path, grid):
    (tmp_path / "tri.obj").write_text(TRI_OBJ)
    with pytest.raises(libvox.UsageError, match="path: embedded null byte"):
        grid.save(str(tmp_path / "out.ply\0.vgrid"))
    assert not (tmp_path / "out.ply").exists()
    grid.save(tmp_path / "out.ply")
    with pytest.raises(libvox.UsageError, match="path: embedded null byte"):
        libvox.load(str(tmp_path / "out.ply\0.vgrid"))
    with pytest.raises(libvox.UsageError, match="source: embedded null byte"):
        libvox.voxelize(str(tmp_path / "tri.obj\0junk"))
    with pytest.raises(libvox.UsageError, match=r"sources\[1\]: embedded null byte"):
        libvox.voxelize_batch([tmp_path / "tri.obj", bytes(tmp_path / "tri.obj") + b"\0"], 4)
    with pytest.raises(libvox.UsageError, match="path: embedded null byte"):
        libvox.save_image(str(tmp_path / "x.png\0.exr"), np.zeros((2, 2, 3)))
    assert issubclass(libvox.UsageError, ValueError)


# 2. An OBJ in Latin-1: the importer's warning comes through (its bytes replaced), as vox-voxelize succeeds with it.
def test_latin1_obj_warns(tmp_path):
    path = tmp_path / "latin1.obj"
    path.write_bytes(("usemtl café\n" + TRI_OBJ).encode("latin-1"))
    with pytest.warns(UserWarning) as record:
        grid = libvox.voxelize(path, resolution=4)
    assert grid.occupied_count > 0
    messages = [str(w.message) for w in record]
    assert any("caf\ufffd" in m for m in messages), messages
    for m in messages:  # 10, last: a warning names the path once
        assert m.count("latin1.obj") == 1, m


# 3. A non-UTF-8 byte in a bad line: the importer's message, not an empty one.
def test_latin1_bad_line_message(tmp_path, tools):
    path = tmp_path / "latin1c.obj"
    path.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \xe9\n")
    with pytest.raises(libvox.InputError, match=r"latin1c.obj:4: bad face index") as e:
        libvox.voxelize(path)
    import subprocess
    cli = subprocess.run([str(tools / "vox-voxelize"), str(path), "-o", str(tmp_path / "x.vgrid")],
                         capture_output=True)
    assert b"latin1c.obj:4: bad face index" in cli.stderr
    assert "\ufffd" in str(e.value) or "\\xe9" in str(e.value)


# 4. No pybind11 "Unable to cast" RuntimeError: wrong types are TypeErrors, out-of-range integers UsageErrors.
@pytest.mark.parametrize("call,error,message", [
    (lambda g: libvox.voxelize((V, F), pitch="0.1"), TypeError, "pitch must be a number, not str"),
    (lambda g: libvox.voxelize((V, F), pitch=1j), TypeError, "pitch must be a number, not complex"),
    (lambda g: libvox.voxelize((V, F), resolution=2 ** 64), libvox.UsageError,
     "resolution must be 1..2097152, got 18446744073709551616"),
    (lambda g: libvox.voxelize((V, F), threads=2 ** 70), libvox.UsageError, "threads must be 1..4096"),
    (lambda g: libvox.render(g, fov="wide"), TypeError, "fov must be a number, not str"),
    (lambda g: libvox.render(g, filter=(3, 1.0)), TypeError, "filter kind must be a str, not int"),
    (lambda g: libvox.render(g, filter=("box", "x")), TypeError, "filter radius must be a number, not str"),
    (lambda g: libvox.render(g, size=(2 ** 64, 4)), libvox.UsageError,
     "size: width must be 1..16384, got 18446744073709551616"),
])
def test_no_cast_runtime_error(grid, call, error, message):
    with pytest.raises(error, match=message):
        call(grid)


def test_non_utf8_paths_work(tmp_path, grid, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / os.fsdecode(b"\xff.obj")).write_text(TRI_OBJ)
    a = libvox.voxelize(b"\xff.obj", resolution=4)
    b = libvox.voxelize("\udcff.obj", resolution=4)
    c = libvox.voxelize(pathlib.Path(os.fsdecode(b"\xff.obj")), resolution=4)
    assert a.occupied_count == b.occupied_count == c.occupied_count > 0
    assert a.source == "\udcff.obj" and os.fsencode(a.source) == b"\xff.obj"
    grid.save(b"\xff.vgrid")
    assert (tmp_path / os.fsdecode(b"\xff.vgrid")).exists()
    back = libvox.load(b"\xff.vgrid")
    assert back.occupied_count == grid.occupied_count and back.source == "\udcff.vgrid"
    import pickle
    assert pickle.loads(pickle.dumps(back)).source == back.source
    with pytest.raises(libvox.InputError, match="missing\ufffd.obj"):  # a message with such a name decodes
        libvox.voxelize(b"missing\xff.obj")


# 5. Anything with __index__ is an integer (numpy's too); a bool is never a number.
def test_numpy_integers_and_bools(grid):
    assert libvox.voxelize((V, F), resolution=np.int64(4)).dims == (4, 4, 4)
    assert libvox.voxelize((V, F), dims=np.int64(4)).dims == (4, 4, 4)
    assert libvox.voxelize((V, F), dims=np.array([4, 3, 2], dtype=np.uint16)).dims == (4, 3, 2)
    assert libvox.voxelize_batch([(V, F)], np.int64(8)).shape == (1, 8, 8, 8)
    assert libvox.render(grid, size=np.array([4, 4])).shape == (4, 4, 3)
    assert libvox.render(grid, size=(4, 4), samples=np.uint8(2), fov=np.float32(30)).shape == (4, 4, 3)
    assert libvox.voxelize((V, F), pitch=np.float32(0.5)).dims == (2, 2, 2)
    for kw in ("resolution", "dims", "pitch", "threads"):
        for value in (True, np.bool_(True)):
            with pytest.raises(TypeError, match=kw):
                libvox.voxelize((V, F), **{kw: value})
    with pytest.raises(TypeError, match="samples must be an int, not bool"):
        libvox.render(grid, size=(4, 4), samples=True)
    with pytest.raises(TypeError, match="weight must be a number, not bool"):
        libvox.render(grid, size=(4, 4), weight=False)
    assert libvox.render(grid, size=(4, 4), shade_back=np.bool_(True)).shape == (4, 4, 3)
    with pytest.raises(TypeError, match="shade_back must be True or False"):
        libvox.render(grid, size=(4, 4), shade_back=1)


# 6 (Ctrl-C) is tested in test_long_calls.py.


# 7. An integer coordinate without an exact double is refused, not rounded.
def test_integer_vertices_exact():
    v = (V * 2 ** 53).astype(np.int64)
    v[1, 0] = 2 ** 53 + 1
    with pytest.raises(libvox.InputError, match=r"vertices: the integer 9007199254740993 has no exact double"):
        libvox.voxelize((v, F), resolution=4)
    with pytest.raises(libvox.InputError, match="has no exact double"):
        libvox.voxelize((np.full((4, 3), 2 ** 64 - 1, dtype=np.uint64), F), resolution=4)
    v[1, 0] = 2 ** 60  # exact: taken
    assert libvox.voxelize((v, F), resolution=4).bounds[1, 0] == 2.0 ** 60
    with pytest.raises(libvox.UsageError, match=r"bounds\[1\]\[0\]: the integer 9007199254740993 has no exact"):
        libvox.voxelize((V, F), bounds=((0, 0, 0), (2 ** 53 + 1, 1, 1)))


# 8. voxelize_batch gives the importer's warnings, and its errors say which source.
def test_batch_warnings_and_errors(tmp_path):
    path = tmp_path / "f.obj"
    path.write_text("mtllib missing.mtl\nusemtl red\n" + TRI_OBJ)
    with pytest.warns(UserWarning) as single:
        libvox.voxelize(path, resolution=4)
    with pytest.warns(UserWarning) as batch:
        libvox.voxelize_batch([(V, F), path], 4)
    assert len(single) == 2 and len(batch) == 2
    for s, b in zip(single, batch):
        assert str(b.message) == "sources[1]: " + str(s.message)
        assert str(b.message).count("f.obj") == 1
    with pytest.raises(libvox.InputError, match=r"^sources\[1\]: faces\[0, 2\] = 10: out of range"):
        libvox.voxelize_batch([(V, F), (V, [[0, 1, 10]])], 8)
    with pytest.raises(libvox.InputError, match=r"^sources\[0\]: .*: is a folder"):
        libvox.voxelize_batch([tmp_path], 8)


# 9. A single path is not a list of sources.
@pytest.mark.parametrize("sources", ["cube.obj", b"cube.obj", pathlib.Path("cube.obj"), 42])
def test_batch_of_one_path(sources):
    with pytest.raises(TypeError, match="sources must be a list of sources"):
        libvox.voxelize_batch(sources, 8)


# 10. Messages name the right cause.
class Broken:
    faces = F

    @property
    def vertices(self):
        raise KeyError("no vertices here")


def test_messages_name_the_cause(grid, tmp_path):
    with pytest.raises(libvox.UsageError, match="bounds: the extent on axis x .* is wider than the largest double"):
        libvox.voxelize((V, F), bounds=((-1e308, 0, 0), (1e308, 1, 1)), resolution=8)
    with pytest.raises(libvox.UsageError, match=r"bounds\[0\]\[0\] must be a finite number, got nan"):
        libvox.voxelize((V, F), bounds=((np.nan, 0, 0), (1, 1, 1)), pitch=0.25)
    # A far eye and a near one are cameras, not "up is parallel" or "eye and look_at must differ".
    assert libvox.render(grid, size=(4, 4), eye=(1e300,) * 3, look_at=(0, 0, 0)).shape == (4, 4, 3)
    near = libvox.render(grid, size=(8, 8), eye=(0.2, 0.2, 1e-300), look_at=(0.2, 0.2, 0), mode="depth")
    assert near.shape == (8, 8)
    with pytest.raises(libvox.UsageError, match="eye and look_at must differ"):
        libvox.render(grid, size=(4, 4), eye=(1, 2, 3), look_at=(1, 2, 3))
    with pytest.raises(libvox.UsageError, match="up must not be zero"):
        libvox.render(grid, size=(4, 4), up=(0, 0, 0))
    with pytest.raises(libvox.UsageError, match="up is parallel to the view direction"):
        libvox.render(grid, size=(4, 4), eye=(0, 0, 5), look_at=(0, 0, 0), up=(0, 0, 1))
    with pytest.raises(TypeError, match="tmax must be a number, not NoneType"):
        grid.intersect([[0, 0, 5]], [[0, 0, -1]], tmax=None)
    with pytest.raises(libvox.InputError, match=r"image: expected shape .* got shape \(0, 4, 3\)"):
        libvox.save_image(tmp_path / "x.png", np.zeros((0, 4, 3)))
    with pytest.raises(KeyError, match="no vertices here"):
        libvox.voxelize(Broken())
    with pytest.raises(libvox.InputError, match="vertices: not an array"):
        libvox.voxelize(([[0, 0, 0], [1, 0], [0, 1, 0]], [[0, 1, 2]]))
    with pytest.raises(libvox.UsageError, match=r"dims\[0\] must be 1..2097152, got 18446744073709551616"):
        libvox.voxelize((V, F), dims=(2 ** 64, 1, 1))


# ---- One catalogue of wrong values for every public function and keyword ----

CATALOGUE = [
    object(), "text", b"bytes", float("nan"), float("inf"), -1, 0, -1.5, 2 ** 70, 1e300, True, False,
    np.int64(3), np.float64(np.nan), np.bool_(True), np.float32(2.5), [], (), [1, [2, 3]], [[1, 2, 3], [4, 5]],
    [float("nan")] * 3, b"\xff\x00.vgrid", "a\0b.vgrid", 1j, {"a": 1},
]


def _calls():
    """(label, names the message may use, call(value, grid, tmp)) for every public function and keyword."""
    g = "g"
    rays = dict(origins=[[0.2, 0.2, 5]], directions=[[0, 0, -1]])
    calls = [("voxelize source", ("source", "vertices", "faces"), lambda x, g, t: libvox.voxelize(x, resolution=4))]
    for kw in ("resolution", "dims", "pitch", "bounds", "method", "fill", "sdf", "fraction", "threads", "progress"):
        calls.append((f"voxelize {kw}", (kw,), lambda x, g, t, kw=kw: libvox.voxelize((V, F), **{kw: x})))
    calls.append(("sdf source", ("source", "vertices", "faces"), lambda x, g, t: libvox.sdf(x, resolution=4)))
    for kw in ("resolution", "dims", "pitch", "bounds", "threads", "progress"):
        calls.append((f"sdf {kw}", (kw,), lambda x, g, t, kw=kw: libvox.sdf((V, F), **{kw: x})))
    for kw in ("points", "signed", "threads"):
        calls.append((f"distance {kw}", (kw,),
                      lambda x, g, t, kw=kw: g.distance(**{"points": [[0, 0, 0]], kw: x})))
    calls.append(("voxelize_batch sources", ("sources",), lambda x, g, t: libvox.voxelize_batch(x, 4)))
    calls.append(("voxelize_batch resolution", ("resolution",), lambda x, g, t: libvox.voxelize_batch([(V, F)], x)))
    for kw in ("fill", "method", "threads", "dense", "progress"):
        calls.append((f"voxelize_batch {kw}", (kw,),
                      lambda x, g, t, kw=kw: libvox.voxelize_batch([(V, F)], 4, **{kw: x})))
    calls.append(("load path", ("path",), lambda x, g, t: libvox.load(x)))
    calls.append(("save path", ("path",), lambda x, g, t: g.save(x)))
    for kw in ("faces", "color", "ascii", "threads", "progress"):
        calls.append((f"save {kw}", (kw,), lambda x, g, t, kw=kw: g.save(t / "m.ply", **{kw: x})))
    calls.append(("save bricks", ("bricks",), lambda x, g, t: g.save(t / "set.vgrid", bricks=x)))
    calls.append(("dense solid", ("solid",), lambda x, g, t: g.dense(x)))
    calls.append(("contains points", ("points",), lambda x, g, t: g.contains(x)))
    calls.append(("colors mode", ("mode",), lambda x, g, t: g.colors(x)))
    for kw in ("faces", "color", "threads"):
        calls.append((f"mesh {kw}", (kw,), lambda x, g, t, kw=kw: g.mesh(**{kw: x})))
    for method in ("intersect", "occluded"):
        for kw in ("origins", "directions", "tmax", "threads", "accel"):
            calls.append((f"{method} {kw}", (kw,),
                          lambda x, g, t, kw=kw, m=method: getattr(g, m)(**{**rays, kw: x})))
    calls.append(("render grid", ("grid",), lambda x, g, t: libvox.render(x, size=(4, 4))))
    for kw in ("size", "mode", "samples", "bounces", "weight", "shade_back", "shadows", "filter", "up", "fov",
               "accel", "threads", "progress"):
        calls.append((f"render {kw}", (kw,),
                       lambda x, g, t, kw=kw: libvox.render(g, **{"size": (4, 4), kw: x})))
    calls.append(("render eye", ("eye",), lambda x, g, t: libvox.render(g, size=(4, 4), eye=x, look_at=(0, 0, 0))))
    calls.append(("render look_at", ("look_at",),
                  lambda x, g, t: libvox.render(g, size=(4, 4), eye=(0, 0, 5), look_at=x)))
    calls.append(("save_image path", ("path",), lambda x, g, t: libvox.save_image(x, np.zeros((2, 2, 3)))))
    calls.append(("save_image image", ("image",), lambda x, g, t: libvox.save_image(t / "i.png", x)))
    return calls


def _value_names(value):
    """A path argument's message may name the argument by its value (the file it could not read)."""
    if isinstance(value, (str, bytes)) and (b"\0" if isinstance(value, bytes) else "\0") not in value:
        return (os.fsdecode(value).encode("utf-8", "replace").decode("utf-8", "replace"),)
    return ()


ALLOWED = (TypeError, libvox.InputError, libvox.UsageError, libvox.LimitError, OSError)


@pytest.mark.parametrize("label,names,call", _calls(), ids=[c[0] for c in _calls()])
def test_catalogue_of_wrong_values(label, names, call, grid, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a bytes path that is valid writes here
    failures = []
    for value in CATALOGUE:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                call(value, grid, tmp_path)
        except ALLOWED as e:
            if isinstance(e, ValueError) and not isinstance(e, (libvox.InputError, libvox.UsageError)):
                failures.append(f"{value!r}: a bare {type(e).__name__}: {e}")
            elif isinstance(e, MemoryError) and not isinstance(e, libvox.LimitError):
                failures.append(f"{value!r}: a bare MemoryError: {e}")
            elif not any(n in str(e) for n in names + _value_names(value)):
                failures.append(f"{value!r}: {type(e).__name__} does not name {names}: {e}")
        except Exception as e:  # noqa: BLE001 -- what the test is about: nothing else may come out
            failures.append(f"{value!r}: {type(e).__name__}: {e}")
    assert not failures, f"{label}:\n" + "\n".join(failures)
