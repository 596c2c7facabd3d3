"""libvox.voxelize equals vox-voxelize cell for cell (cells and primitive ids), for the course's scenes, OBJ, PLY and
glTF, every method, with and without fill; and arrays in equal files in."""

import numpy as np
import pytest

import libvox
from conftest import BUNNY_PLY, SCENES, SEED, assert_same_grid, cli_voxelize, info_cells, read_ascii_ply

COURSE = [
    SCENES / "scene5_02_spheres.txt",
    SCENES / "scene2_13_rotated_squashed_sphere.txt",
    SCENES / "scene5_05_sphere_triangles.txt",
    SCENES / "scene5_07_bunny_mesh_1k.txt",
    SCENES / "scene5_12_nested_transformations.txt",
    SCENES / "scene6_03_sphere_plane.txt",
    SEED / "6837" / "scenes" / "scene2_15_crazy_transforms.txt",
]
MESHES = [
    SCENES / "teapot.obj",
    SEED / "6837" / "scenes" / "bunny_1k.obj",
    BUNNY_PLY,
    SEED / "gltf" / "Duck" / "glTF-Binary" / "Duck.glb",
    SEED / "gltf" / "Box" / "glTF" / "Box.gltf",
    SEED / "gltf" / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf",
]
METHODS = ["exact", "sat", "bbox", "center"]


@pytest.mark.parametrize("scene", COURSE + MESHES, ids=lambda p: p.name)
@pytest.mark.parametrize("fill", [False, True], ids=["surface", "fill"])
def test_same_cells_as_cli(tools, tmp_path, scene, fill):
    res = 48
    args = ["--res", res] + (["--fill"] if fill else [])
    cli = libvox.load(cli_voxelize(tools, tmp_path, scene, *args))
    ours = libvox.voxelize(scene, resolution=res, fill=fill or None)
    assert ours.occupied_count > 0
    assert_same_grid(ours, cli)


@pytest.mark.filterwarnings("ignore:.*nothing filled")  # two triangles and a sphere: bbox and center fill nothing
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("scene", [SCENES / "scene5_05_sphere_triangles.txt", SCENES / "teapot.obj"],
                         ids=lambda p: p.name)
def test_every_method(tools, tmp_path, scene, method):
    for fill in (False, True):
        args = ["--res", 40, "--method", method] + (["--fill"] if fill else [])
        cli = libvox.load(cli_voxelize(tools, tmp_path, scene, *args))
        ours = libvox.voxelize(scene, resolution=40, method=method, fill=fill)
        assert ours.method == method
        assert_same_grid(ours, cli)


def test_default_grid_dims_and_bounds_options(tools, tmp_path):
    scene = SCENES / "scene5_07_bunny_mesh_1k.txt"
    assert_same_grid(libvox.voxelize(scene), libvox.load(cli_voxelize(tools, tmp_path, scene)))
    assert_same_grid(libvox.voxelize(scene, dims=(7, 30, 11)),
                     libvox.load(cli_voxelize(tools, tmp_path, scene, "--grid", 7, 30, 11)))
    bounds = ((-0.05, 0.0, -0.1), (0.2, 0.3, 0.05))
    ours = libvox.voxelize(scene, dims=(20, 20, 20), bounds=bounds)
    cli = libvox.load(cli_voxelize(tools, tmp_path, scene, "--grid", 20, 20, 20, "--bounds",
                                   *bounds[0], *bounds[1]))
    assert_same_grid(ours, cli)


def test_against_vox_info_json(tools, tmp_path):
    """The cells through vox-info's JSON, a path independent of libvox.load."""
    scene = SCENES / "scene5_05_sphere_triangles.txt"
    path = cli_voxelize(tools, tmp_path, scene, "--res", 24)
    info, ijk, prims = info_cells(tools, path)
    ours = libvox.voxelize(scene, resolution=24)
    assert list(ours.dims) == info["dims"]
    assert np.array_equal(ours.indices, ijk)
    offsets, ids = ours.cell_primitives
    assert [list(ids[offsets[c]:offsets[c + 1]]) for c in range(len(ijk))] == prims
    assert np.array_equal(ours.counts, [len(p) for p in prims])
    assert info["bounds"]["min"] == list(ours.bounds[0]) and info["bounds"]["max"] == list(ours.bounds[1])


def test_arrays_equal_file():
    vertices, faces = read_ascii_ply(BUNNY_PLY)
    from_file = libvox.voxelize(BUNNY_PLY, resolution=128)
    from_arrays = libvox.voxelize((vertices, faces), resolution=128)
    assert from_arrays.source == "<arrays>"
    assert_same_grid(from_arrays, from_file)
    assert from_file.dense().shape == from_file.dims


def test_float32_widened_exactly():
    vertices, faces = read_ascii_ply(BUNNY_PLY)
    v32 = vertices.astype(np.float32)
    a = libvox.voxelize((v32, faces.astype(np.int32)), resolution=64)
    b = libvox.voxelize((v32.astype(np.float64), faces), resolution=64)
    assert_same_grid(a, b)
    # float32 moves the coordinates, so the grids of the rounded and the exact bunny differ somewhere.
    exact = libvox.voxelize((vertices, faces), resolution=64)
    assert not np.array_equal(exact.bounds, a.bounds)


def test_duck_typed_mesh_and_lists():
    class Mesh:
        vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
        faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.uint32)

    a = libvox.voxelize(Mesh(), resolution=8)
    b = libvox.voxelize((Mesh.vertices.tolist(), Mesh.faces.tolist()), resolution=8)
    c = libvox.voxelize([Mesh.vertices[::1, :].copy(order="F"), Mesh.faces.astype(np.int64)], resolution=8)
    assert_same_grid(a, b)
    assert_same_grid(a, c)
    # Cell counts of a closed tetrahedron's surface; the fill adds its inside.
    f = libvox.voxelize(Mesh(), resolution=8, fill=True)
    assert f.solid_count > 0
    assert not np.any(_solid_mask(f) & f.dense(solid=False))  # solid cells meet no surface


def test_pitch():
    v = np.array([[0, 0, 0], [1.0, 0, 0], [0, 0.5, 0.25]])
    g = libvox.voxelize((v, [[0, 1, 2]]), pitch=0.1)
    assert g.dims == (10, 5, 3)
    assert np.allclose(g.pitch, 0.1)
    assert np.allclose(g.bounds.mean(axis=0), [0.5, 0.25, 0.125])
    assert np.all(g.bounds[0] <= [0, 0, 0]) and np.all(g.bounds[1] >= [1, 0.5, 0.25])


def test_grid_views():
    g = libvox.voxelize(SCENES / "scene5_02_spheres.txt", resolution=16, fill=True)
    n = g.occupied_count
    assert g.indices.shape == (n, 3) and g.indices.dtype == np.int32
    assert g.points.shape == (n, 3) and g.points.dtype == np.float64
    assert g.counts.shape == (n,) and g.counts.dtype == np.int32
    offsets, ids = g.cell_primitives
    assert offsets.shape == (n + 1,) and ids.dtype == np.uint32 and not ids.flags.writeable
    assert np.array_equal(np.diff(offsets), g.counts)
    # The transform maps indices to centres (up to rounding); the points are the exact midpoints.
    h = np.c_[g.indices, np.ones(n)] @ g.transform.T
    assert np.allclose(h[:, :3], g.points, rtol=0, atol=1e-12)
    dense = g.dense()
    assert dense.dtype == np.bool_ and dense.shape == g.dims
    assert dense.sum() == n + g.solid_count - np.sum(g.dense(solid=False) & _solid_mask(g))
    assert np.array_equal(np.argwhere(g.dense(solid=False)), g.indices[np.lexsort(g.indices.T[::-1])])
    assert np.all(g.contains(g.points))
    solid_centres = g.solid_indices * g.pitch + g.bounds[0] + g.pitch / 2
    assert np.all(g.contains(solid_centres))
    empty = np.argwhere(~dense)
    assert not np.any(g.contains(empty * g.pitch + g.bounds[0] + g.pitch / 2))
    assert not np.any(g.contains([[1e9, 0, 0]]))


def _solid_mask(g):
    m = np.zeros(g.dims, dtype=bool)
    m[tuple(g.solid_indices.T)] = True
    return m
