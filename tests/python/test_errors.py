"""Bad input raises the documented exception with a clear message, and the interpreter lives on."""

import os

import numpy as np
import pytest

import libvox
from conftest import SCENES

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
F = np.array([[0, 1, 2]])


def test_exception_hierarchy():
    assert issubclass(libvox.InputError, ValueError)
    assert issubclass(libvox.UsageError, ValueError)
    assert issubclass(libvox.LimitError, MemoryError)


@pytest.mark.parametrize("vertices,faces,error,message", [
    (V.astype(np.complex128), F, TypeError, "vertices must hold floats"),
    (V.astype(bool), F, TypeError, "vertices must hold floats"),
    (V.astype(str), F, TypeError, "vertices must hold floats"),
    (V, F.astype(np.float64), TypeError, "faces must hold integers"),
    (V[:, :2], F, libvox.InputError, r"vertices: expected an array of shape \(N, 3\), got shape \(3, 2\)"),
    (V.ravel(), F, libvox.InputError, r"got shape \(9,\)"),
    (V, F[:, :2], libvox.InputError, r"faces: expected an array of shape \(F, 3\)"),
    (np.where(np.eye(3, dtype=bool), np.nan, V), F, libvox.InputError, r"vertices\[0, 0\] is nan"),
    (np.where(np.eye(3, dtype=bool), np.inf, V), F, libvox.InputError, r"vertices\[0, 0\] is inf"),
    (V, [[0, 1, 3]], libvox.InputError, r"faces\[0, 2\] = 3: out of range for 3 vertices"),
    (V, [[0, -1, 2]], libvox.InputError, r"faces\[0, 1\] = -1: out of range"),
    (np.empty((0, 3)), np.empty((0, 3), dtype=int), libvox.InputError, "vertices: empty array"),
    (V, np.empty((0, 3), dtype=int), libvox.InputError, "faces: empty array"),
    (np.array([[2 ** 60 + 1, 0, 0]], dtype=np.int64).repeat(3, 0), F, libvox.InputError, "has no exact double"),
])
def test_bad_arrays(vertices, faces, error, message):
    with pytest.raises(error, match=message):
        libvox.voxelize((vertices, faces), resolution=4)


def test_bad_sources_and_options(tmp_path):
    with pytest.raises(TypeError, match="source must be a path"):
        libvox.voxelize(42)
    with pytest.raises(libvox.InputError, match="missing.obj"):
        libvox.voxelize(tmp_path / "missing.obj")
    with pytest.raises(libvox.UsageError, match="a grid file, not a scene: libvox.load reads it"):
        libvox.voxelize(tmp_path / "g.vgrid")
    with pytest.raises(libvox.InputError, match="unknown scene format"):
        libvox.voxelize(SCENES / "README.md")
    with pytest.raises(libvox.UsageError, match="at most one of resolution, dims and pitch"):
        libvox.voxelize((V, F), resolution=4, dims=(4, 4, 4))
    with pytest.raises(libvox.UsageError, match="method"):
        libvox.voxelize((V, F), method="magic")
    with pytest.raises(libvox.UsageError, match="resolution must be 1"):
        libvox.voxelize((V, F), resolution=0)
    with pytest.raises(TypeError, match="resolution must be an int"):
        libvox.voxelize((V, F), resolution=4.5)
    with pytest.raises(libvox.UsageError, match="bounds"):
        libvox.voxelize((V, F), bounds=((1, 1, 1), (0, 0, 0)))
    with pytest.raises(libvox.UsageError, match="bounds"):
        libvox.voxelize((V, F), bounds=(1, 2, 3))
    with pytest.raises(libvox.UsageError, match="pitch"):
        libvox.voxelize((V, F), pitch=-1)
    with pytest.raises(libvox.UsageError, match="threads"):
        libvox.voxelize((V, F), threads=0)
    with pytest.raises(TypeError, match="fill"):
        libvox.voxelize((V, F), fill="yes")


def test_corrupt_files(tmp_path):
    scene = tmp_path / "bad.obj"
    scene.write_text("v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(libvox.InputError, match=r"bad.obj:2"):
        libvox.voxelize(scene)
    scene.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(libvox.InputError, match=r"bad.obj:3"):
        libvox.voxelize(scene)
    good = tmp_path / "g.vgrid"
    libvox.voxelize((V, F), resolution=4).save(good)
    data = good.read_bytes()
    (tmp_path / "short.vgrid").write_bytes(data[: len(data) // 2])
    with pytest.raises(libvox.InputError, match="short.vgrid"):
        libvox.load(tmp_path / "short.vgrid")
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 0xFF
    (tmp_path / "flip.vgrid").write_bytes(bytes(flipped))
    with pytest.raises(libvox.InputError, match="flip.vgrid"):
        libvox.load(tmp_path / "flip.vgrid")
    (tmp_path / "empty.vgrid").write_bytes(b"")
    with pytest.raises(libvox.InputError, match="empty.vgrid"):
        libvox.load(tmp_path / "empty.vgrid")
    with pytest.raises(TypeError):
        libvox.load(3)


def test_huge_requests():
    with pytest.raises(libvox.LimitError, match="MiB"):
        libvox.voxelize(SCENES / "teapot.obj", resolution=2 ** 21)
    with pytest.raises(libvox.UsageError):
        libvox.voxelize((V, F), dims=(2 ** 22, 1, 1))
    big = libvox.voxelize((V * 1e-6, F), dims=(2 ** 20, 2 ** 20, 1), bounds=((0, 0, -1), (1, 1, 1)))
    assert big.occupied_count > 0
    with pytest.raises(libvox.LimitError, match="dense"):
        big.dense()
    with pytest.raises(libvox.LimitError):
        libvox.voxelize_batch([(V, F)] * 4, resolution=2 ** 14)
    grid = libvox.voxelize((V, F), resolution=4)
    with pytest.raises(libvox.UsageError, match="width"):
        libvox.render(grid, size=(0, 10))
    with pytest.raises(libvox.UsageError, match="width must be 1..16384"):
        libvox.render(grid, size=(16385, 1))


def test_bad_rays():
    grid = libvox.voxelize((V, F), resolution=4)
    with pytest.raises(libvox.InputError, match="same number"):
        grid.intersect(np.zeros((3, 3)), np.ones((2, 3)))
    with pytest.raises(libvox.InputError, match=r"origins\[1, 2\] is nan"):
        grid.intersect([[0, 0, 0], [0, 0, np.nan]], np.ones((2, 3)))
    with pytest.raises(libvox.InputError, match="tmax"):
        grid.intersect(np.zeros((3, 3)), np.ones((3, 3)), tmax=[1, 2])
    with pytest.raises(TypeError):
        grid.intersect(np.zeros((3, 3)), np.ones((3, 3)).astype(object))
    with pytest.raises(libvox.UsageError):
        grid.intersect(np.zeros((3, 3)), np.ones((3, 3)), accel="kd")
    with pytest.raises(libvox.UsageError, match="mode"):
        libvox.render(grid, mode="xray")
    with pytest.raises(libvox.UsageError, match="eye and look_at"):
        libvox.render(grid, eye=(0, 0, 1))


def test_outputs(tmp_path):
    grid = libvox.voxelize((V, F), resolution=4)
    image = libvox.render(grid, size=(8, 8))
    with pytest.raises(libvox.UsageError, match="unknown image format"):
        libvox.save_image(tmp_path / "x.abc", image)
    with pytest.raises(OSError):
        libvox.save_image(tmp_path / "no" / "x.png", image)
    with pytest.raises(libvox.InputError, match="image"):
        libvox.save_image(tmp_path / "x.png", np.zeros((4, 4, 2)))
    if os.geteuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o500)
        with pytest.raises(OSError):
            grid.save(ro / "g.vgrid")
    # The interpreter lives on and the module still works.
    assert libvox.voxelize((V, F), resolution=4).occupied_count > 0


# Issue 45, defect 13: the Python side's messages.
def test_sdf_names_the_source_once():
    with pytest.raises(libvox.LimitError) as caught:
        libvox.sdf((V, F), dims=4096)  # 512 GiB of float64: refused before any work
    message = str(caught.value)
    assert message.startswith("<arrays>: sdf() needs about") and message.count("<arrays>") == 1, message


def test_calls_that_do_not_fit_name_the_argument():
    with pytest.raises(TypeError, match=r"^sdf\(\) got an unexpected keyword argument 'method' \(it takes source, "
                                        r"resolution, dims, pitch, bounds, threads, progress\)$"):
        libvox.sdf((V, F), method="exact")
    with pytest.raises(TypeError, match=r"^sdf\(\) takes 1 positional argument \(source\) but 2 were given; "
                                        r"resolution, dims, pitch, bounds, threads, progress are keyword-only"):
        libvox.sdf((V, F), 8)
    grid = libvox.voxelize((V, F), resolution=4)
    with pytest.raises(TypeError, match=r"^Grid.dense\(\) takes at most 1 positional argument \(solid\) but 2 were"):
        grid.dense(True, 1)
    with pytest.raises(TypeError, match=r"^Grid.save\(\) got multiple values for argument 'path'$"):
        grid.save("a.vgrid", path="b.vgrid")
    with pytest.raises(TypeError, match=r"^Grid.distance\(\) missing required argument 'points'$"):
        grid.distance()
    with pytest.raises(TypeError, match=r"^render\(\): grid must be a libvox.Grid, not str$"):
        libvox.render("bunny.vgrid")
    with pytest.raises(TypeError, match=r"^Grid.save\(\) needs a libvox.Grid to work on, not int$"):
        libvox.Grid.save(42, "x.vgrid")


def test_none_is_named_as_none():
    grid = libvox.voxelize((V, F), resolution=4)
    with pytest.raises(TypeError, match=r"^points must be an array of numbers \(or a sequence of them\), not "
                                        r"NoneType$"):
        grid.distance(None)
    with pytest.raises(TypeError, match=r"not a list of other objects$"):
        grid.distance([[None, None, None]])
    with pytest.raises(TypeError, match=r"not dtype object$"):
        grid.distance(np.array([[1, 2, 3]], dtype=object))


# Every function and method, called with an unknown keyword and with one positional argument too many: a TypeError
# naming the call and what is wrong, never pybind11's "incompatible function arguments".
def audit_calls(tmp_path):
    grid = libvox.voxelize((V, F), resolution=4)
    grid.save(tmp_path / "g.vgrid")
    ray = ([[0.2, 0.2, -1]], [[0, 0, 1]])
    return {
        "voxelize": (libvox.voxelize, ((V, F),)),
        "sdf": (libvox.sdf, ((V, F),)),
        "surface": (libvox.surface, ((V, F),)),
        "voxelize_batch": (libvox.voxelize_batch, ([(V, F)],)),
        "load": (libvox.load, (tmp_path / "g.vgrid",)),
        "render": (libvox.render, (grid,)),
        "save_image": (libvox.save_image, (tmp_path / "i.png", np.zeros((2, 2, 3), np.float32))),
        "_voxelize_loop": (libvox._libvox._voxelize_loop, ([(V, F)], 4)),
        "_grid_from_state": (libvox._libvox._grid_from_state, (grid.__getstate__(),)),
        "Grid.save": (grid.save, (tmp_path / "h.vgrid",)),
        "Grid.dense": (grid.dense, ()),
        "Grid.contains": (grid.contains, ([[0, 0, 0]],)),
        "Grid.intersect": (grid.intersect, ray),
        "Grid.occluded": (grid.occluded, ray),
        "Grid.distance": (grid.distance, ([[0, 0, 0]],)),
        "Grid.mesh": (grid.mesh, ()),
        "Grid.surface": (grid.surface, ()),
        "Grid.colors": (grid.colors, ()),
        "Grid.__repr__": (grid.__repr__, ()),
        "Grid.__reduce__": (grid.__reduce__, ()),
        "Grid.__getstate__": (grid.__getstate__, ()),
        "Grid.__setstate__": (grid.__setstate__, (grid.__getstate__(),)),
    }


def test_audit_covers_every_function(tmp_path):
    native = libvox._libvox
    functions = {n for n in dir(native) if callable(getattr(native, n)) and not isinstance(getattr(native, n), type)
                 and not n.startswith("__")}
    methods = {"Grid." + n for n, v in vars(libvox.Grid).items() if callable(v) and (not n.startswith("__") or n in (
        "__repr__", "__reduce__", "__getstate__", "__setstate__"))}
    assert functions | methods == set(audit_calls(tmp_path)) == set(AUDITED)


def positional_count(function):
    """The parameters that can be given by position, from the signature on the docstring's first line."""
    import ast
    first = function.__doc__.splitlines()[0]
    params = first[first.index("(") + 1:first.rindex(") -> ")]
    args = ast.parse(f"def f({params}): pass").body[0].args
    return len(args.posonlyargs + args.args) - (1 if args.args and args.args[0].arg == "self" else 0)


AUDITED = ["voxelize", "sdf", "surface", "voxelize_batch", "load", "render", "save_image", "_voxelize_loop", "_grid_from_state",
           "Grid.save", "Grid.dense", "Grid.contains", "Grid.intersect", "Grid.occluded", "Grid.distance", "Grid.mesh",
           "Grid.surface", "Grid.colors", "Grid.__repr__", "Grid.__reduce__", "Grid.__getstate__", "Grid.__setstate__"]


@pytest.mark.parametrize("name", AUDITED)
def test_wrong_keyword_and_extra_positional(tmp_path, name):
    function, args = audit_calls(tmp_path)[name]
    short = name.split(".")[-1]
    with pytest.raises(TypeError) as caught:
        function(*args, no_such_argument=1)
    message = str(caught.value)
    assert "incompatible" not in message and "'no_such_argument'" in message and f"{short}()" in message, message
    extra = list(args) + [None] * (positional_count(function) - len(args) + 1)
    with pytest.raises(TypeError) as caught:
        function(*extra)
    message = str(caught.value)
    assert "incompatible" not in message and "positional argument" in message and f"{short}()" in message, message
