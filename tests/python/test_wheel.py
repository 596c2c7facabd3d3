"""The wheel (issue 36, item 4; docs/python.md "Install"): `pip wheel --no-build-isolation --no-index --no-deps
./python` on the tests' build folder makes a platform wheel holding the module and libvox_oiio.so, which installs
into a fresh venv offline without compiling anything, and works there from a folder outside the repository:
voxelize arrays, pickle a Grid, save an image (the OpenImageIO module found beside the extension, in the venv)."""

import os
import subprocess
import sys
import sysconfig
import textwrap
import time
import zipfile

import pytest

from conftest import ROOT

# The venv's script: everything from the installed package, nothing from the repository or the build folder.
SCRIPT = textwrap.dedent("""
    import os, pickle, sys
    import numpy as np
    import libvox

    venv = sys.argv[1]
    package = os.path.dirname(libvox.__file__)
    assert package.startswith(venv), package
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    grid = libvox.voxelize((v, f), resolution=16, fill=True)
    assert grid.dims == (16, 16, 16) and grid.solid_count > 0
    back = pickle.loads(pickle.dumps(grid))
    assert np.array_equal(back.dense(), grid.dense())
    assert back.__getstate__() == grid.__getstate__()
    libvox.save_image("tet.png", libvox.render(back, size=(32, 24)))
    with open("tet.png", "rb") as png:
        assert png.read(8) == b"\\x89PNG\\r\\n\\x1a\\n"
    with open("/proc/self/maps") as maps:
        oiio = {line.split()[-1] for line in maps if line.rstrip().endswith("libvox_oiio.so")}
    assert oiio == {os.path.join(package, "libvox_oiio.so")}, oiio
    print("ok", libvox.__version__)
""")


def build_dir():
    if not os.environ.get("LIBVOX_TOOLS_DIR"):
        pytest.skip("LIBVOX_TOOLS_DIR not set: no build folder to make the wheel from")
    return os.environ.get("LIBVOX_BUILD_DIR") or os.environ["LIBVOX_TOOLS_DIR"]


def run(cmd, **kwargs):
    proc = subprocess.run(cmd, capture_output=True, text=True, **kwargs)
    assert proc.returncode == 0, f"{' '.join(map(str, cmd))}:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout


def test_wheel_installs_offline_and_works(tmp_path):
    env = dict(os.environ, LIBVOX_BUILD_DIR=build_dir(), LIBVOX_JOBS=os.environ.get("LIBVOX_JOBS", "2"))
    env.pop("PYTHONPATH", None)
    dist = tmp_path / "dist"
    run([sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-index", "--no-deps", "-w", dist,
         ROOT / "python"], env=env)
    wheels = list(dist.glob("libvox-*.whl"))
    assert len(wheels) == 1, wheels
    wheel = wheels[0]

    # A platform wheel for this interpreter (cp311-cp311-linux_x86_64 on Debian 12), not py3-none-any.
    py = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    assert wheel.name.endswith(f"-{py}-{py}-{platform}.whl"), wheel.name
    names = set(zipfile.ZipFile(wheel).namelist())
    assert f"libvox/_libvox{sysconfig.get_config_var('EXT_SUFFIX')}" in names
    assert {"libvox/libvox_oiio.so", "libvox/__init__.py", "libvox/__init__.pyi", "libvox/py.typed"} <= names

    venv = tmp_path / "venv"
    run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv], env=env)
    start = time.monotonic()
    out = run([venv / "bin" / "pip", "install", "--no-index", wheel], env=env)
    seconds = time.monotonic() - start
    assert "Successfully installed libvox" in out
    assert "Building" not in out and "setup.py" not in out  # nothing compiled or built at install
    assert seconds < 30, f"pip install took {seconds:.1f} s"

    work = tmp_path / "elsewhere"  # outside the repository: nothing importable by accident
    work.mkdir()
    (work / "check.py").write_text(SCRIPT)
    out = run([venv / "bin" / "python", "-I", "check.py", str(venv)], cwd=work, env=env)
    assert out.startswith("ok ")
    assert (work / "tet.png").stat().st_size > 0
