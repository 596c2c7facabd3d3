"""Invariants of distances, signs, volumes and round trips, held by property-based tests (Hypothesis; issue 45).

Over random closed, open, inside-out and self-intersecting meshes, random bounds (around, inside, cutting, outside
the scene), every overlap method, small resolutions and power-of-two scales:
- the --sdf band equals the dense field (libvox.sdf) at the band's cells, which equals Grid.distance at the cell
  centres, bit for bit, sign included; the band holds exactly the cells the dense field puts within HALF cells;
- the sign is the generalized winding number's decision (inside where |w| >= 0.5), computed here independently,
  wherever |w| is more than 1e-9 from 0.5;
- fractions lie in [0, 1] and sum to the exact volume of the solid inside the bounds;
- save/load (.vgrid, .npz) and pickle round trips are equal;
- a scene scaled by 2^k has its answers times 2^k, bit for bit.

CI runs a fixed seed (derandomize) and VOX_HYPOTHESIS_EXAMPLES examples per property (default 25); a longer run by
hand: `VOX_HYPOTHESIS_EXAMPLES=2000 pytest tests/python/test_properties.py`. Each counterexample found is kept as an
@example of its property (regression).
"""

import math
import os
import pickle

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import libvox  # noqa: E402
from conftest import box  # noqa: E402

EXAMPLES = int(os.environ.get("VOX_HYPOTHESIS_EXAMPLES", "25"))
PROPERTY = settings(max_examples=EXAMPLES, derandomize=True, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
METHODS = ["exact", "sat", "bbox", "center"]
# "fill: ... nothing filled" is the fill telling an open or empty case what it did, not a failure here.
pytestmark = pytest.mark.filterwarnings("ignore:.*nothing filled")

# ---- Meshes ----

def concat(*meshes):
    vs, fs, n = [], [], 0
    for v, f in meshes:
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    return np.concatenate(vs), np.concatenate(fs)


# Coordinates on a grid of eighths: faces then fall on cell boundaries and cell-centre planes, the adversarial cases.
eighths = st.integers(-16, 24).map(lambda n: n / 8)


@st.composite
def boxes(draw):
    lo = [draw(eighths) for _ in range(3)]
    size = [draw(st.integers(1, 16)) / 8 for _ in range(3)]
    return [lo, [a + s for a, s in zip(lo, size)]]


@st.composite
def tetrahedra(draw):
    while True:
        p = np.array([[draw(eighths) for _ in range(3)] for _ in range(4)])
        det = np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]]))
        if abs(det) > 1e-3:
            break
    if det < 0:
        p[[1, 2]] = p[[2, 1]]
    return p, np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]], dtype=np.int64)


@st.composite
def meshes(draw):
    """(kind, vertices, faces, exact volume or None)."""
    kind = draw(st.sampled_from(["box", "tetra", "inside_out", "two_boxes", "open", "soup"]))
    if kind == "box":
        lo, hi = draw(boxes())
        v, f = box(lo, hi)
        return kind, v, f, (lo, hi)
    if kind == "tetra":
        v, f = draw(tetrahedra())
        return kind, v, f, None
    if kind == "inside_out":
        lo, hi = draw(boxes())
        v, f = box(lo, hi, inward=True)
        return kind, v, f.copy(), None
    if kind == "two_boxes":  # overlapping: self-intersecting, winding number 2 where they overlap
        return (kind, *concat(box(*draw(boxes())), box(*draw(boxes()))), None)
    if kind == "open":
        v, f = box(*draw(boxes()))
        keep = draw(st.lists(st.booleans(), min_size=6, max_size=6).filter(lambda k: 0 < sum(k) < 6))
        f = f.reshape(6, 2, 3)[np.array(keep)].reshape(-1, 3)
        return kind, v, f, None
    n = draw(st.integers(1, 6))
    v = np.array([[draw(eighths) for _ in range(3)] for _ in range(3 * n)])
    return kind, v, np.arange(3 * n, dtype=np.int64).reshape(n, 3), None


@st.composite
def bounds_for(draw, v):
    """None (the scene's), or bounds around, inside, cutting or outside the mesh's box."""
    how = draw(st.sampled_from(["scene", "around", "inside", "cutting", "outside"]))
    lo, hi = v.min(axis=0), v.max(axis=0)
    span = np.maximum(hi - lo, 0.25)
    if how == "scene":
        return None
    pick = lambda a, b: [draw(st.integers(a, b)) / 8 for _ in range(3)]  # noqa: E731
    if how == "around":
        return (lo - span * 0.25 - pick(0, 4)).tolist(), (hi + span * 0.25 + pick(0, 4)).tolist()
    if how == "inside":
        a = lo + span * 0.25
        return a.tolist(), (a + np.maximum(span * 0.5, 0.125)).tolist()
    if how == "cutting":
        a = lo + span * 0.5 - pick(0, 8)
        return a.tolist(), (a + span + pick(1, 8)).tolist()
    a = hi + pick(1, 8)
    return a.tolist(), (a + pick(1, 8)).tolist()


def dims_strategy():
    return st.tuples(st.integers(1, 10), st.integers(1, 10), st.integers(1, 10))


# ---- Independent references ----

def winding_numbers(points, v, f):
    """The generalized winding number of the triangles at each point (van Oosterom and Strackee's solid angle)."""
    t = v[f]  # (F, 3, 3)
    out = np.zeros(len(points))
    for start in range(0, len(points), 4096):
        p = points[start:start + 4096]
        a, b, c = (t[None, :, k, :] - p[:, None, :] for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("pfi,pfi->pf", a, np.cross(b, c))
        den = la * lb * lc + np.einsum("pfi,pfi->pf", a, b) * lc + np.einsum("pfi,pfi->pf", b, c) * la + \
            np.einsum("pfi,pfi->pf", c, a) * lb
        out[start:start + 4096] = (2 * np.arctan2(det, den)).sum(axis=1) / (4 * math.pi)
    return out


def centres(g, ijk):
    """Cell centres as libvox computes them: the midpoint of the cell's two boundaries b(i) and b(i+1)."""
    lo, hi = np.array(g.bounds[0]), np.array(g.bounds[1])
    n = np.array(g.dims)
    b0 = lo + (hi - lo) * ijk / n
    b1 = lo + (hi - lo) * (ijk + 1) / n
    return 0.5 * (b0 + b1)


def voxelize_or_refuse(*args, **kwargs):
    """A grid, or None when libvox refuses the request with one of its own exceptions (never anything else)."""
    try:
        return libvox.voxelize(*args, **kwargs)
    except (libvox.InputError, libvox.UsageError, libvox.LimitError):
        return None


# ---- Properties ----

@PROPERTY
@given(data=st.data(), mesh=meshes(), dims=dims_strategy(), method=st.sampled_from(METHODS),
       half=st.sampled_from([1.0, 2.5, 3.0]))
def test_band_equals_dense_field_equals_point_queries(data, mesh, dims, method, half):
    kind, v, f, _ = mesh
    bounds = data.draw(bounds_for(v))
    g = voxelize_or_refuse((v, f), dims=dims, bounds=bounds, method=method, sdf=half)
    if g is None:
        return
    field = libvox.sdf((v, f), dims=dims, bounds=bounds)
    assert field.shape == tuple(g.dims)
    assert not np.isnan(field).any()
    indices, values = g.sdf
    assert len(np.unique(indices, axis=0)) == len(indices)
    assert ((indices >= 0) & (indices < np.array(g.dims))).all()
    # The band is the dense field at its cells, bit for bit, sign included.
    assert np.array_equal(field[tuple(indices.T)], values)
    # And holds every cell the field puts within HALF smallest cell edges.
    edge = min((np.array(g.bounds[1]) - np.array(g.bounds[0])) / np.array(g.dims))
    within = np.argwhere(np.abs(field) <= half * edge)
    assert np.array_equal(np.unique(within, axis=0), np.unique(indices, axis=0))
    # Grid.distance at every cell centre is the field, bit for bit.
    ijk = np.indices(field.shape).reshape(3, -1).T
    d, prim, closest = g.distance(centres(g, ijk))
    assert np.array_equal(d, field.reshape(-1))
    assert ((prim >= 0) & (prim < len(f))).all()


@PROPERTY
@given(data=st.data(), mesh=meshes(), dims=dims_strategy())
def test_sign_is_the_winding_number(data, mesh, dims):
    kind, v, f, _ = mesh
    bounds = data.draw(bounds_for(v))
    try:
        field = libvox.sdf((v, f), dims=dims, bounds=bounds)
    except (libvox.InputError, libvox.UsageError, libvox.LimitError):
        return
    g = libvox.voxelize((v, f), dims=dims, bounds=bounds)
    ijk = np.indices(field.shape).reshape(3, -1).T
    p = centres(g, ijk)
    w = np.abs(winding_numbers(p, v, f))
    d = field.reshape(-1)
    decided = (np.abs(w - 0.5) > 1e-9) & (d != 0)
    wrong = decided & ((d < 0) != (w >= 0.5))
    assert not wrong.any(), (f"{wrong.sum()} of {decided.sum()} signs differ from the winding number, e.g. at "
                             f"{p[wrong][:3].tolist()}: w {w[wrong][:3].tolist()}, d {d[wrong][:3].tolist()}")


def box_volume_inside(lo, hi, bounds):
    blo, bhi = bounds
    return float(np.prod([max(0.0, min(hi[a], bhi[a]) - max(lo[a], blo[a])) for a in range(3)]))


@PROPERTY
@given(data=st.data(), lohi=boxes(), dims=dims_strategy(), fill=st.booleans())
def test_fractions_sum_to_the_volume_inside_the_bounds(data, lohi, dims, fill):
    lo, hi = lohi
    v, f = box(lo, hi)
    bounds = data.draw(bounds_for(v))
    g = voxelize_or_refuse((v, f), dims=dims, bounds=bounds, fraction=True, fill=fill or None)
    if g is None:
        return
    fr = g.fractions
    assert len(fr) == len(g.indices)
    assert not np.isnan(fr).any() and (fr >= 0).all() and (fr <= 1).all()
    blo, bhi = np.array(g.bounds[0]), np.array(g.bounds[1])
    cell = np.prod((bhi - blo) / np.array(g.dims))
    # Occupied cells by their fractions, the fill's solid cells (wholly inside, DESIGN.md) by their volume.
    total = (fr.sum() + len(g.solid_indices)) * cell
    exact = box_volume_inside(lo, hi, (blo, bhi))
    assert abs(total - exact) <= 1e-12 * max(exact, cell), (total, exact)


@PROPERTY
@given(mesh=meshes(), dims=dims_strategy(), method=st.sampled_from(METHODS), fill=st.booleans())
def test_round_trips_are_equal(tmp_path_factory, mesh, dims, method, fill):
    kind, v, f, volume = mesh
    fraction = volume is not None
    g = voxelize_or_refuse((v, f), dims=dims, method=method, fill=fill or None, sdf=2, fraction=fraction)
    if g is None:
        return
    folder = tmp_path_factory.mktemp("rt")
    copies = [pickle.loads(pickle.dumps(g)), libvox.load(_saved(g, folder / "g.vgrid"))]
    for c in copies:
        assert c.dims == g.dims and np.array_equal(c.bounds, g.bounds) and c.method == g.method
        assert np.array_equal(c.indices, g.indices) and np.array_equal(c.solid_indices, g.solid_indices)
        assert np.array_equal(c.sdf[0], g.sdf[0]) and np.array_equal(c.sdf[1], g.sdf[1])
        assert np.array_equal(c.fractions, g.fractions)
        assert np.array_equal(c.cell_primitives[0], g.cell_primitives[0])
        assert np.array_equal(c.cell_primitives[1], g.cell_primitives[1])
    npz = np.load(_saved(g, folder / "g.npz"))
    assert np.array_equal(np.argwhere(npz["occupancy"]), g.indices[np.lexsort(g.indices.T[::-1])])
    sdf = npz["sdf"]
    assert np.array_equal(sdf[tuple(g.sdf[0].T)], g.sdf[1])
    assert np.isnan(sdf).sum() == sdf.size - len(g.sdf[1])


def _saved(g, path):
    g.save(str(path))
    return str(path)


@PROPERTY
@given(mesh=meshes(), dims=dims_strategy(), k=st.integers(-1000, 1000), fraction=st.booleans())
@example(mesh=("box", *box([0, 0, 0], [1, 1, 1]), ([0, 0, 0], [1, 1, 1])), dims=(4, 4, 4), k=520, fraction=True)
@example(mesh=("box", *box([0, 0, 0], [1, 1, 1]), ([0, 0, 0], [1, 1, 1])), dims=(4, 4, 4), k=-1000, fraction=True)
def test_scaled_scenes_give_scaled_answers(mesh, dims, k, fraction):
    kind, v, f, volume = mesh
    fraction = fraction and volume is not None
    scale = math.ldexp(1.0, k)
    g1 = voxelize_or_refuse((v, f), dims=dims, sdf=2, fraction=fraction)
    if g1 is None:
        return
    gk = voxelize_or_refuse((v * scale, f), dims=dims, sdf=2, fraction=fraction)
    assert gk is not None, f"refused at scale 2^{k} what scale 1 accepts"
    assert np.array_equal(gk.bounds, g1.bounds * scale)
    assert np.array_equal(gk.indices, g1.indices) and np.array_equal(gk.solid_indices, g1.solid_indices)
    assert np.array_equal(gk.sdf[0], g1.sdf[0])
    assert np.array_equal(gk.sdf[1], g1.sdf[1] * scale)
    assert np.array_equal(gk.fractions, g1.fractions)
    p1 = g1.points
    d1, prim1, c1 = g1.distance(p1)
    dk, primk, ck = gk.distance(p1 * scale)
    assert np.array_equal(dk, d1 * scale) and np.array_equal(primk, prim1) and np.array_equal(ck, c1 * scale)
