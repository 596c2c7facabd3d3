#!/usr/bin/env bash
# Installs the Debian 12 packages libvox needs, idempotently: nothing is fetched when all are present.
# Usage: scripts/install-deps.sh [--bench] [--meshlab] [--clients] [--fuzz] [--format] [--list]
# --list prints the packages the other options name, one a line, and installs nothing (scripts/check-commands.py).
set -euo pipefail
packages=(build-essential cmake ninja-build pkg-config python3
  libcgal-dev libopenmesh-dev libopenimageio-dev libtinygltf-dev libstb-dev nlohmann-json3-dev
  libtbb-dev libcli11-dev libgtest-dev
  openmpi-bin libopenmpi-dev
  libopenvdb-dev  # vox-export writes .vdb (export/vdb_writer.cpp)
  # The Python package (python/, docs/python.md) and its tests.
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-setuptools python3-venv python3-pip
  # Packaging (issue 36): cpack's Debian package (dpkg-shlibdeps), man pages from --help; Dask for the Python test that
  # voxelizes over a LocalCluster; ccache, used by the build when present.
  dpkg-dev help2man python3-dask python3-distributed ccache
  # cpack's Debian generator runs `file` (CPackDeb.cmake) besides dpkg-shlibdeps: missing on a minbase Debian (issue 45).
  file
  # Property-based tests (issue 45): Hypothesis for the Python package, RapidCheck for the library.
  python3-hypothesis librapidcheck-dev
  # The viewer page (vox-export -o OUT.html, viewer/): its script is bundled at build time with Node.js and npm.
  nodejs)
# npm: Debian's package, unless an npm is already there (NodeSource's nodejs brings its own, and Debian's npm would
# pull Debian's older nodejs over it).
command -v npm >/dev/null || packages+=(npm)
list=0
for arg in "$@"; do
  case $arg in
    --list) list=1 ;;
    # bench/python_bench.py compares with Open3D (Debian's 0.16) and draws its bars with tqdm; bench/surface_bench.py
    # with scikit-image's marching cubes and OpenVDB's meshToLevelSet + volumeToMesh (pyopenvdb).
    --bench) packages+=(libbenchmark-dev libembree-dev python3-open3d python3-tqdm python3-matplotlib python3-skimage
                        python3-openvdb) ;;
    --meshlab) packages+=(meshlab xvfb xauth) ;;
    # Real clients of exported meshes (tests/cli/export_*.sh); numpy for Blender's glTF importer.
    # python3-openvdb (pyopenvdb) reads exported .vdb files back (tests/cli/export_voxel_formats.sh).
    # chromium: the viewer page's tests (tests/viewer/) in headless Chromium.
    --clients) packages+=(meshlab xvfb xauth assimp-utils blender python3-numpy python3-openvdb chromium) ;;
    --fuzz) packages+=(clang libclang-rt-14-dev) ;;  # libFuzzer and the sanitizer runtimes (scripts/fuzz.sh)
    --format) packages+=(clang-format git) ;;  # scripts/check-format.sh
    *) echo "install-deps.sh: unknown option $arg" >&2; exit 1 ;;
  esac
done
if [ $list = 1 ]; then
  printf '%s\n' "${packages[@]}"
  exit 0
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps.sh: installing ${missing[*]}" >&2
SUDO=""
[ "$(id -u)" = 0 ] || SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
