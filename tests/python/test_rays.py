"""Grid.intersect / Grid.occluded equal the brute force bit for bit, and vox-trace's depth image; libvox.render equals
vox-trace pixel for pixel."""

import math
import re

import numpy as np
import pytest

import libvox
from conftest import SCENES, cli_voxelize, run_tool

SCENE_FILES = [
    SCENES / "scene5_07_bunny_mesh_1k.txt",
    SCENES / "scene5_02_spheres.txt",
    SCENES / "scene2_13_rotated_squashed_sphere.txt",
    SCENES / "scene6_03_sphere_plane.txt",
    SCENES / "teapot.obj",
]


def random_rays(grid, n, seed):
    """Rays from around the grid towards it, axis-aligned rays through cell corners and edges, and rays whose
    directions have zero components: the cases where a walk can go wrong."""
    rng = np.random.default_rng(seed)
    lo, hi = grid.bounds
    size = hi - lo
    origins = lo - 0.5 * size + 2 * size * rng.random((n, 3))
    targets = lo + size * rng.random((n, 3))
    directions = targets - origins
    # Through lattice points along the axes.
    m = n // 4
    corner = rng.integers(0, np.array(grid.dims) + 1, size=(m, 3))
    points = lo + corner * grid.pitch
    axis = rng.integers(0, 3, size=m)
    d = np.zeros((m, 3))
    d[np.arange(m), axis] = rng.choice([-1.0, 1.0], size=m)
    origins[:m] = points - 2 * size.max() * d
    directions[:m] = d
    # Zero components, and an unnormalized length.
    directions[m:2 * m, rng.integers(0, 3)] = 0.0
    directions[2 * m:3 * m] *= 1e-3
    return origins, directions


@pytest.mark.parametrize("scene", SCENE_FILES, ids=lambda p: p.name)
@pytest.mark.parametrize("method", ["exact", "sat", "bbox"])
def test_intersect_equals_brute_force(scene, method):
    grid = libvox.voxelize(scene, resolution=24, method=method)
    origins, directions = random_rays(grid, 4000, 7)
    t, prim, normal = grid.intersect(origins, directions)
    tb, pb, nb = grid.intersect(origins, directions, accel="none")
    assert (prim >= 0).sum() > 100  # enough hits to mean something
    assert np.array_equal(t, tb)  # bit for bit (inf for misses on both sides)
    assert np.array_equal(prim, pb)
    assert np.array_equal(normal, nb)
    assert np.all(np.isinf(t[prim < 0])) and np.all(normal[prim < 0] == 0)
    hit = prim >= 0
    assert np.allclose(np.linalg.norm(normal[hit], axis=1), 1)
    # A hit point lies where t says, and tmax cuts it off exactly.
    tmax = np.where(hit, t, 1.0)
    assert np.array_equal(grid.occluded(origins, directions, tmax), hit | (tb <= 1.0))
    below = np.nextafter(tmax, -np.inf)
    assert np.array_equal(grid.intersect(origins, directions, below)[1][hit] >= 0,
                          grid.intersect(origins, directions, below, accel="none")[1][hit] >= 0)
    assert np.array_equal(grid.occluded(origins, directions), grid.occluded(origins, directions, accel="none"))
    assert np.array_equal(grid.occluded(origins, directions), hit)
    # The uniform walk (every cell crossed, no jumps over empty boxes) gives the same answers.
    tu, pu, nu = grid.intersect(origins, directions, accel="uniform")
    assert np.array_equal(t, tu) and np.array_equal(prim, pu) and np.array_equal(normal, nu)
    assert np.array_equal(grid.occluded(origins, directions, accel="uniform"), hit)


def test_intersect_threads_and_shapes():
    grid = libvox.voxelize(SCENES / "scene5_02_spheres.txt", resolution=16)
    origins, directions = random_rays(grid, 1000, 3)
    one = grid.intersect(origins, directions, threads=1)
    two = grid.intersect(origins, directions, threads=2)
    for a, b in zip(one, two):
        assert np.array_equal(a, b)
    t, prim, normal = grid.intersect(np.empty((0, 3)), np.empty((0, 3)))
    assert t.shape == (0,) and prim.shape == (0,) and normal.shape == (0, 3)
    assert prim.dtype == np.int64 and t.dtype == np.float64


def camera_rays(eye, look_at, up, fov, w, h):
    """Primary rays by DESIGN.md's camera convention (pixel centres, vertical fov), as unit directions."""
    d = np.asarray(look_at, float) - eye
    d /= np.linalg.norm(d)
    right = np.cross(d, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, d)
    tan = math.tan(math.radians(fov) / 2)
    x, y = np.meshgrid(np.arange(w), np.arange(h))
    u = (2 * (x + 0.5) / w - 1) * tan * w / h
    v = (1 - 2 * (y + 0.5) / h) * tan
    dirs = d + u[..., None] * right + v[..., None] * true_up
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    return np.broadcast_to(eye, dirs.shape).reshape(-1, 3), dirs.reshape(-1, 3)


def same_image_file(a, b):
    """Two image files written by the library hold the same bytes, but for the capture date OpenEXR headers carry."""
    def undated(path):
        return re.sub(rb"\d{4}:\d\d:\d\d \d\d:\d\d:\d\d", b"0" * 19, path.read_bytes())
    return undated(a) == undated(b)


def camera_for(grid):
    """A camera looking at the grid's centre from the front, a little above and right."""
    centre = grid.bounds.mean(axis=0)
    size = np.ptp(grid.bounds, axis=0).max()
    eye = centre + size * np.array([0.4, 0.5, 1.8])
    return dict(eye=tuple(eye), look_at=tuple(centre), up=(0.0, 1.0, 0.0), fov=35.0)


def test_intersect_equals_vox_trace_depth(tools, tmp_path):
    scene = SCENES / "scene5_07_bunny_mesh_1k.txt"
    path = cli_voxelize(tools, tmp_path, scene, "--res", 32)
    grid = libvox.load(path)
    w, h = 96, 72
    CAMERA = camera_for(grid)
    exr = tmp_path / "cli_depth.exr"
    run_tool(tools, "vox-trace", path, "-o", exr, "--mode", "depth", "--size", w, h, "--eye", *CAMERA["eye"],
             "--look-at", *CAMERA["look_at"], "--up", *CAMERA["up"], "--fov", CAMERA["fov"])
    depth = libvox.render(grid, (w, h), "depth", **CAMERA)
    mine = tmp_path / "py_depth.exr"
    libvox.save_image(mine, depth)
    assert same_image_file(exr, mine)  # render() writes what vox-trace writes
    origins, dirs = camera_rays(np.array(CAMERA["eye"]), CAMERA["look_at"], CAMERA["up"], CAMERA["fov"], w, h)
    t, prim, _ = grid.intersect(origins, dirs)
    ray_depth = np.where(prim >= 0, t, 0).reshape(h, w).astype(np.float32)
    hit_render, hit_rays = depth > 0, ray_depth > 0
    assert hit_render.sum() > 0.2 * w * h
    # The directions are computed here in numpy, so rays on a silhouette may fall either side of it.
    assert np.mean(hit_render != hit_rays) < 0.01
    both = hit_render & hit_rays
    assert np.allclose(depth[both], ray_depth[both], rtol=1e-5)


@pytest.mark.parametrize("mode", ["shade", "voxels", "normals", "depth", "count"])
@pytest.mark.parametrize("scene", [SCENES / "scene5_05_sphere_triangles.txt", SCENES / "scene6_03_sphere_plane.txt"],
                         ids=lambda p: p.name)
def test_render_equals_vox_trace(tools, tmp_path, scene, mode):
    path = cli_voxelize(tools, tmp_path, scene, "--res", 20)
    grid = libvox.load(path)
    cli = tmp_path / "cli.exr"
    run_tool(tools, "vox-trace", path, "-o", cli, "--mode", mode, "--size", 64, 48, "--samples", 4)
    image = libvox.render(grid, size=(64, 48), mode=mode, samples=4)
    assert image.dtype == np.float32
    assert image.shape == ((48, 64) if mode == "depth" else (48, 64, 3))
    assert np.ptp(image) > 0
    mine = tmp_path / "py.exr"
    libvox.save_image(mine, image)
    assert same_image_file(cli, mine)
    # The brute force gives the same pixels, as vox-trace's --accel none does (the count of cells visited aside).
    if mode != "count":
        assert np.array_equal(image, libvox.render(grid, size=(64, 48), mode=mode, samples=4, accel="none"))


def test_render_options_as_vox_trace(tools, tmp_path):
    scene = SCENES / "scene5_05_sphere_triangles.txt"
    path = cli_voxelize(tools, tmp_path, scene)
    cli = tmp_path / "cli.png"
    run_tool(tools, "vox-trace", path, "-o", cli, "--size", 40, 30, "--bounces", 2, "--shade-back", "--filter",
             "tent", 1.5, "--samples", 9, "--no-shadows", "--fov", 50)
    image = libvox.render(libvox.load(path), (40, 30), bounces=2, shade_back=True, filter=("tent", 1.5), samples=9,
                          shadows=False, fov=50)
    mine = tmp_path / "py.png"
    libvox.save_image(mine, image)
    assert same_image_file(cli, mine)
