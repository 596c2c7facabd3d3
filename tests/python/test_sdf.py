"""libvox.voxelize(..., sdf=HALF) and Grid.sdf (issue 38): the CLI's band bit for bit, the unit cube's exact
distances, pickling, and wrong values refused."""
import pickle

import numpy as np
import pytest

import libvox
from conftest import cli_voxelize

CUBE = __import__("pathlib").Path(__file__).resolve().parents[1] / "data" / "unit_cube.obj"


def test_band_equals_the_cli_and_the_cubes_exact_distances(tools, tmp_path):
    g = libvox.voxelize(CUBE, resolution=10, sdf=3)
    indices, values = g.sdf
    assert indices.dtype == np.int32 and values.dtype == np.float64
    assert indices.shape == (len(values), 3) and len(values) > 0
    assert g.sdf_half_width == 3.0
    cli = libvox.load(cli_voxelize(tools, tmp_path, CUBE, "--res", "10", "--sdf"))
    assert np.array_equal(cli.sdf[0], indices) and np.array_equal(cli.sdf[1], values)
    lo, hi = np.array(g.bounds[0]), np.array(g.bounds[1])
    cell = (hi - lo) / np.array(g.dims)
    assert np.allclose(cell, cell[0], rtol=0, atol=1e-15)  # --sdf with resolution: cubic cells
    c = lo + (indices + 0.5) * cell
    inside = np.all((c > 0) & (c < 1), axis=1)
    outside_d = np.linalg.norm(np.maximum(np.maximum(-c, c - 1), 0), axis=1)
    expected = np.where(inside, -np.min(np.minimum(c, 1 - c), axis=1), outside_d)
    assert np.max(np.abs(values - expected)) < 1e-12
    assert np.all(np.abs(values) <= 3 * cell[0] * (1 + 1e-12))


def test_band_pickles_and_is_empty_without_sdf():
    g = libvox.voxelize(CUBE, resolution=8, sdf=1.5)
    back = pickle.loads(pickle.dumps(g))
    assert np.array_equal(back.sdf[1], g.sdf[1]) and back.sdf_half_width == 1.5
    plain = libvox.voxelize(CUBE, resolution=8)
    assert plain.sdf[0].shape == (0, 3) and plain.sdf[1].shape == (0,) and plain.sdf_half_width == 0.0


@pytest.mark.parametrize("bad", [0, -1, 65, float("nan"), float("inf")])
def test_bad_half_widths_are_usage_errors(bad):
    with pytest.raises(libvox.UsageError, match="sdf"):
        libvox.voxelize(CUBE, resolution=4, sdf=bad)


@pytest.mark.parametrize("bad", ["3", True, [3]])
def test_wrong_types_are_type_errors(bad):
    with pytest.raises(TypeError, match="sdf"):
        libvox.voxelize(CUBE, resolution=4, sdf=bad)


def test_dense_sdf_equals_the_band_and_grid_distance():
    """libvox.sdf on voxelize(sdf=)'s grid: the band's values at its indices bit for bit, Grid.distance at the cell
    centres too, and both signs inside the cube."""
    box = ((-0.4, -0.3, -0.2), (1.5, 1.4, 1.3))
    field = libvox.sdf(CUBE, dims=(11, 9, 8), bounds=box)
    g = libvox.voxelize(CUBE, dims=(11, 9, 8), bounds=box, sdf=3)
    assert field.dtype == np.float64 and field.shape == tuple(g.dims)
    indices, values = g.sdf
    assert np.array_equal(field[tuple(indices.T)], values)
    lo, hi = np.array(g.bounds[0]), np.array(g.bounds[1])
    ijk = np.indices(field.shape).reshape(3, -1).T
    b = lo[None, :] + (hi - lo)[None, :] * ijk / np.array(g.dims)
    b1 = lo[None, :] + (hi - lo)[None, :] * (ijk + 1) / np.array(g.dims)
    centres = 0.5 * (b + b1)  # as libvox computes a centre: the midpoint of the cell's two boundaries
    d, prim, closest = g.distance(centres)
    assert np.array_equal(d, field.reshape(-1))  # a closed cube: the fill's sign is the winding number's
    assert d.dtype == np.float64 and prim.dtype == np.int64 and closest.shape == (len(d), 3)
    assert np.all((prim >= 0) & (prim < 12))
    assert np.allclose(np.linalg.norm(centres - closest, axis=1), np.abs(d), rtol=0, atol=1e-12)
    assert (field < 0).any() and (field > 0).any()


def test_grid_distance_signed_unsigned_and_bad_points():
    g = libvox.voxelize(CUBE, resolution=4)
    d, prim, closest = g.distance([[0.5, 0.5, 0.5], [2, 0.5, 0.5], [0.5, 0.5, 1]])
    assert np.allclose(d, [-0.5, 1, 0], atol=1e-15) and d[2] == 0
    assert np.allclose(closest[1], [1, 0.5, 0.5])
    u, _, _ = g.distance(np.array([[0.5, 0.5, 0.5]], dtype=np.float32), signed=False)
    assert u[0] == 0.5
    e = g.distance(np.zeros((0, 3)))
    assert e[0].shape == (0,) and e[1].shape == (0,) and e[2].shape == (0, 3)
    with pytest.raises(libvox.InputError, match="points"):
        g.distance([[0, 0, float("nan")]])
    with pytest.raises(libvox.InputError, match="points"):
        g.distance([[0, 0]])
    with pytest.raises(TypeError, match="points"):
        g.distance("points")
    with pytest.raises(TypeError, match="signed"):
        g.distance([[0, 0, 0]], signed="yes")


def test_dense_sdf_refuses_bad_grids():
    with pytest.raises(libvox.LimitError, match="sdf"):  # 8 TiB, refused from the plan before voxelizing
        libvox.sdf(CUBE, dims=(2 ** 20, 2 ** 20, 1))
    with pytest.raises(libvox.UsageError, match="resolution"):
        libvox.sdf(CUBE, resolution=0)
    with pytest.raises(libvox.UsageError, match="at most one"):
        libvox.sdf(CUBE, resolution=4, dims=4)


def centres_of(g):
    """Every cell centre in C order, as libvox computes a centre (the midpoint of the cell's two boundaries)."""
    lo, hi = np.array(g.bounds[0]), np.array(g.bounds[1])
    ijk = np.indices(tuple(g.dims)).reshape(3, -1).T
    return 0.5 * (lo + (hi - lo) * ijk / np.array(g.dims) + lo + (hi - lo) * (ijk + 1) / np.array(g.dims))


@pytest.mark.parametrize("bounds, inside", [(((0.25,) * 3, (0.75,) * 3), 512), (((0.5,) * 3, (1.5,) * 3), 64)])
def test_bounds_cutting_the_cube_sign_like_grid_distance(bounds, inside):
    """Issue 45 #6: the surfaces outside the bounds count; the band, libvox.sdf and Grid.distance agree bit for bit."""
    field = libvox.sdf(CUBE, dims=8, bounds=bounds)
    g = libvox.voxelize(CUBE, dims=8, bounds=bounds, sdf=3)
    indices, values = g.sdf
    assert np.array_equal(field[tuple(indices.T)], values)
    d = g.distance(centres_of(g))[0]
    assert np.array_equal(d, field.reshape(-1))
    assert np.count_nonzero(field < 0) == inside


def test_center_method_signs_like_grid_distance():
    """Issue 45 #7: method="center" leaves the fill's status wrong; the band's signs must not come from it."""
    g = libvox.voxelize(CUBE, resolution=12, method="center", sdf=3)
    indices, values = g.sdf
    field = libvox.sdf(CUBE, resolution=12)
    assert np.array_equal(field[tuple(indices.T)], values)
    d = g.distance(centres_of(g))[0]
    assert np.array_equal(d, field.reshape(-1))
    c = centres_of(g)[np.ravel_multi_index(tuple(indices.T), tuple(g.dims))]
    inside = np.all((c > 0) & (c < 1), axis=1)
    assert np.array_equal(values < 0, inside)
