"""Builds the libvox package: the extension module and the OpenImageIO module are built by CMake and Ninja on the
repository this folder belongs to (not by setuptools, which would compile the library serially), then copied into
the package.

Environment:
  LIBVOX_BUILD_DIR  CMake build folder to use (default: build-python/ at the repository's top). An existing build
                    folder (such as scripts/test.sh's) is reused: only the module is built in it.
  LIBVOX_JOBS       Ninja's parallel jobs (default: Ninja's own).
"""

import os
import pathlib
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent


def cmake_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    start = text.index("project(libvox VERSION ") + len("project(libvox VERSION ")
    return text[start:].split()[0]


class BuildWithCMake(build_py):
    """Copies the Python files, then builds _libvox with CMake and adds it and libvox_oiio.so to the package."""

    def run(self):
        super().run()
        build = pathlib.Path(os.environ.get("LIBVOX_BUILD_DIR", ROOT / "build-python")).resolve()
        configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-G", "Ninja", "-DVOX_PYTHON=ON"]
        cache = build / "CMakeCache.txt"
        python = os.path.realpath(sys.executable)  # a venv's python is a link to the system's
        if not cache.exists():
            # A fresh folder builds what the package needs, for this Python: no tests (they need the seed scenes).
            configure += ["-DCMAKE_BUILD_TYPE=Release", "-DVOX_TESTS=OFF", f"-DPython3_EXECUTABLE={python}"]
        else:
            for line in cache.read_text().splitlines():
                if line.startswith("Python3_EXECUTABLE:") and os.path.realpath(line.split("=", 1)[1]) != python:
                    sys.exit(f"setup.py: {build} builds for {line.split('=', 1)[1]}, not {python}: "
                             "set LIBVOX_BUILD_DIR to another folder")
        subprocess.run(configure, check=True, stdout=subprocess.DEVNULL)
        ninja = ["cmake", "--build", str(build), "--target", "_libvox"]
        if os.environ.get("LIBVOX_JOBS"):
            ninja += ["--parallel", os.environ["LIBVOX_JOBS"]]
        subprocess.run(ninja, check=True)
        built = build / "python" / "libvox"
        target = pathlib.Path(self.build_lib) / "libvox"
        target.mkdir(parents=True, exist_ok=True)
        modules = list(built.glob("_libvox*.so")) + [built / "libvox_oiio.so"]
        for f in modules:
            self.copy_file(str(f), str(target / f.name))


class BinaryDistribution(Distribution):
    def has_ext_modules(self):
        return True


setup(
    name="libvox",
    version=cmake_version(),
    description="Exact voxelization and exact grid ray tracing for numpy arrays",
    packages=["libvox"],
    package_data={"libvox": ["*.pyi", "py.typed"]},
    python_requires=">=3.9",
    install_requires=["numpy"],
    cmdclass={"build_py": BuildWithCMake},
    distclass=BinaryDistribution,
    zip_safe=False,
)
