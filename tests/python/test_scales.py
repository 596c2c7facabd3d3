"""The numeric domain (issue 45, defects 1, 9, 10 and 11; docs/limits.md "Numeric domain"): a cube's band, dense
field, Grid.distance and fractions at scale 2^k equal its answers at scale 1 times 2^k bit for bit, from 2^-1000 to
2^1000 and at offsets 0 and 1e6; every save, load and pickle of these grids is equal; what lies outside the domain
(cells narrower than the coordinates' spacing, points or bounds too far from the scene) is refused with one line."""

import pickle

import numpy as np
import pytest

import libvox

# The unit cube [0, 1]^3, outward.
V = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=np.float64)
F = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
              [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]])


def centres(g):
    lo, hi, dims = np.array(g.bounds[0]), np.array(g.bounds[1]), np.array(g.dims)
    ijk = np.indices(tuple(g.dims)).reshape(3, -1).T
    return 0.5 * ((lo + (hi - lo) * ijk / dims) + (lo + (hi - lo) * (ijk + 1) / dims))


def answers(offset, k, tmp_path):
    v = np.ldexp(V + offset, k)
    g = libvox.voxelize((v, F), resolution=8, sdf=3, fraction=True)
    field = libvox.sdf((v, F), resolution=8)
    d, prim, closest = g.distance(centres(g))
    for path in (tmp_path / "g.vgrid", tmp_path / "g.npz"):
        g.save(path)
    back = libvox.load(tmp_path / "g.vgrid")
    for h in (back, pickle.loads(pickle.dumps(g))):
        assert np.array_equal(h.sdf[0], g.sdf[0]) and np.array_equal(h.sdf[1], g.sdf[1])
        assert np.array_equal(h.fractions, g.fractions) and np.array_equal(h.bounds, g.bounds)
    with np.load(tmp_path / "g.npz") as z:
        assert np.array_equal(z["sdf"][tuple(g.sdf[0].T)], g.sdf[1])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.npz", "g.vgrid"]  # no temporary left
    return g, field, d, prim, closest


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_answers_scale_bit_for_bit(offset, tmp_path):
    g1, field1, d1, prim1, closest1 = answers(offset, 0, tmp_path)
    assert np.isfinite(field1).all() and ((g1.fractions >= 0) & (g1.fractions <= 1)).all()
    assert (field1 < 0).any() and (g1.fractions > 0).any()
    for k in range(-1000, 1001, 50):
        g, field, d, prim, closest = answers(offset, k, tmp_path)
        assert g.dims == g1.dims and g.solid_count == g1.solid_count > 0  # the fill once gave up at 2^400
        assert np.array_equal(np.array(g.bounds), np.ldexp(np.array(g1.bounds), k))
        assert np.array_equal(g.sdf[0], g1.sdf[0])
        assert np.array_equal(g.sdf[1], np.ldexp(g1.sdf[1], k)), k
        assert np.array_equal(field, np.ldexp(field1, k)), k
        assert np.array_equal(d, np.ldexp(d1, k)) and np.array_equal(prim, prim1), k
        assert np.array_equal(closest, np.ldexp(closest1, k)), k
        assert np.array_equal(g.fractions, g1.fractions), k


def test_huge_cube_band_inside_the_grid_and_saved(tmp_path):
    """Defect 1: side 1.3e154 and more squared the band's reach to infinity; keys past the grid overflowed the
    heap in save("x.npz")."""
    for side in (1.3e154, 1e300):
        g = libvox.voxelize((V * side, F), resolution=8, sdf=3)
        keys, values = g.sdf
        assert len(keys) and (keys < np.array(g.dims)).all() and (keys >= 0).all()
        assert len({tuple(k) for k in keys}) == len(keys) and np.isfinite(values).all()
        for name in ("x.npz", "x.vgrid"):
            g.save(tmp_path / name)
        h = libvox.load(tmp_path / "x.vgrid")
        assert np.array_equal(h.sdf[1], values)
        assert np.array_equal(pickle.loads(pickle.dumps(g)).sdf[1], values)
        with np.load(tmp_path / "x.npz") as z:
            assert np.array_equal(z["sdf"][tuple(keys.T)], values)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.npz", "x.vgrid"]


def test_offset_1e16_right_or_refused(tmp_path):
    """Defect 9: the unit cube moved to 1e16 gave 56 of 64 NaN fractions, which save wrote and load refused. There
    1e16 + 1 rounds to 1e16: the cube is a point, with no volume, in cells wider than the doubles' spacing."""
    v = V + 1e16
    g = libvox.voxelize((v, F), resolution=4, sdf=3, fraction=True)
    assert np.array_equal(g.fractions, np.zeros_like(g.fractions)) and np.isfinite(g.sdf[1]).all()
    g.save(tmp_path / "p.vgrid")
    assert np.array_equal(libvox.load(tmp_path / "p.vgrid").fractions, g.fractions)
    assert np.array_equal(pickle.loads(pickle.dumps(g)).sdf[1], g.sdf[1])
    # A cube of side 16 there in 64 cells: cells of 1/4 where doubles lie 2 apart, so boundaries coincide.
    v = V * 16 + 1e16
    for kwargs in ({"fraction": True}, {"sdf": 3}):
        with pytest.raises(libvox.InputError, match=r"narrower than the spacing 2 of doubles at 1e\+16: cell") as e:
            libvox.voxelize((v, F), resolution=64, **kwargs)
        assert "\n" not in str(e.value)
    with pytest.raises(libvox.InputError, match="coincide"):
        libvox.sdf((v, F), resolution=64)


def test_far_points_right_or_refused():
    """Defect 11: points 1.3e154 and more away got +inf and a wrong primitive."""
    g = libvox.voxelize((V - 0.5, F), resolution=4)
    far = 2.0 ** 498
    d, prim, closest = g.distance([[far, 0.25, 0.125], [0.25, -far, 0.125]])
    assert (d == far).all() and (prim >= 0).all() and (np.abs(closest) <= 0.5).all()
    for x in (1e300, -1e160):
        with pytest.raises(libvox.InputError, match=r"^points\[0, 1\] is .*within \+-1\.63669530394807"):
            g.distance([[0, x, 0]])
    with pytest.raises(libvox.InputError, match=r"sdf: cell centres reach 7.5e\+299 \(bounds 1e\+300\)"):
        libvox.sdf((V, F), dims=(4, 4, 4), bounds=((-1e300,) * 3, (1e300,) * 3))


def test_an_empty_band_saves_loads_and_pickles(tmp_path):
    """A band that reaches no cell centre (bounds inside the cube, further than HALF cells from its faces) is a legal
    grid: it saved as "0 cells and 0 values at half-width 2; not written" (a RuntimeError) before (probe of issue
    45). Now every writer takes it and every reader gives it back."""
    from conftest import box
    v, f = box((0, 0, 0), (1, 1, 1))
    g = libvox.voxelize((v, f), dims=8, sdf=2, bounds=((0.25,) * 3, (0.75,) * 3))
    assert g.sdf_half_width == 2 and len(g.sdf[1]) == 0
    for c in (pickle.loads(pickle.dumps(g)), libvox.load(_save(g, tmp_path / "g.vgrid"))):
        assert c.sdf_half_width == 2 and len(c.sdf[1]) == 0 and np.array_equal(c.indices, g.indices)
    npz = np.load(_save(g, tmp_path / "g.npz"))
    assert np.isnan(npz["sdf"]).all()


def _save(g, path):
    g.save(str(path))
    return str(path)
