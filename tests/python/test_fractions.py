"""libvox.voxelize(..., fraction=True) and Grid.fractions (issue 38): the CLI's file bit for bit, a box's and a
hollow box's exact volumes, a ball's 4/3 pi r^3, pickling, and the refusals as UsageError."""
import math
import pickle

import numpy as np
import pytest

import libvox
from conftest import box, cli_voxelize


def total_volume(g):
    """Fractions times cell volumes plus the solid cells, summed exactly enough (math.fsum)."""
    lo, hi = np.array(g.bounds[0]), np.array(g.bounds[1])
    cell = float(np.prod((hi - lo) / np.array(g.dims)))
    return math.fsum(list(g.fractions) + [1.0] * g.solid_count) * cell


def test_box_volume_and_the_cli_bit_for_bit(tools, tmp_path):
    lo, hi = (0.13, 0.21, 0.05), (0.47, 0.71, 0.67)
    v, f = box(lo, hi)
    bounds = ((0, 0, 0), (0.7, 0.9, 0.8))
    g = libvox.voxelize((v, f), dims=(7, 9, 8), bounds=bounds, fraction=True)
    fr = g.fractions
    assert fr.dtype == np.float64 and fr.shape == (g.occupied_count,)
    assert np.all((fr >= 0) & (fr <= 1)) and np.count_nonzero((fr > 0) & (fr < 1)) > 50
    exact = 0.34 * 0.5 * 0.62
    assert abs(total_volume(g) - exact) < 1e-12 * exact
    obj = tmp_path / "box.obj"
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in v) +
                   "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in f))
    cli = libvox.load(cli_voxelize(tools, tmp_path, obj, "--grid", "7", "9", "8", "--bounds", "0", "0", "0", "0.7",
                                   "0.9", "0.8", "--fraction"))
    assert np.array_equal(cli.indices, g.indices) and np.array_equal(cli.fractions, fr)
    assert np.array_equal(cli.solid_indices, g.solid_indices)


def test_a_closed_cavity_stays_empty():
    """A hollow box (inner shell oriented inward): fraction implies a fill by winding number, so the cavity's cells
    are not solid and the total is the shell's volume."""
    outer, inner = box((0, 0, 0), (1, 1, 1)), box((0.3, 0.3, 0.3), (0.6, 0.6, 0.6), inward=True)
    v = np.vstack([outer[0], inner[0]])
    f = np.vstack([outer[1], inner[1] + 8])
    g = libvox.voxelize((v, f), dims=9, bounds=((-0.05,) * 3, (1.05,) * 3), fraction=True)
    assert abs(total_volume(g) - (1 - 0.027)) < 1e-12


def test_ball_adds_up_to_four_thirds_pi_r_cubed(tmp_path):
    scene = tmp_path / "ball.txt"
    scene.write_text("OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n"
                     "Background { color 0 0 0 }\n"
                     "Materials { numMaterials 1 PhongMaterial { diffuseColor 1 0 0 } }\n"
                     "Group { numObjects 1 MaterialIndex 0 Sphere { center 0.1 -0.2 0.3 radius 0.7 } }\n")
    g = libvox.voxelize(scene, resolution=13, fraction=True)
    exact = 4 / 3 * math.pi * 0.7 ** 3
    assert abs(total_volume(g) - exact) < 1e-12 * exact


def test_fractions_pickle_and_are_empty_without():
    g = libvox.voxelize(box((0, 0, 0), (1, 1, 1)), dims=5, bounds=((-0.1,) * 3, (1.1,) * 3), fraction=True)
    back = pickle.loads(pickle.dumps(g))
    assert np.array_equal(back.fractions, g.fractions) and len(g.fractions) == g.occupied_count
    assert libvox.voxelize(box((0, 0, 0), (1, 1, 1)), dims=5).fractions.shape == (0,)


def test_refusals_are_usage_errors():
    v, f = box((0, 0, 0), (1, 1, 1))
    with pytest.raises(libvox.UsageError, match="open edges"):
        libvox.voxelize((v, f[:-2]), resolution=4, fraction=True)
    with pytest.raises(libvox.UsageError, match="center"):
        libvox.voxelize((v, f), resolution=4, method="center", fraction=True)
    with pytest.raises(TypeError, match="fraction"):
        libvox.voxelize((v, f), resolution=4, fraction="yes")


@pytest.mark.parametrize("bounds, want", [
    (((0.25,) * 3, (0.75,) * 3), 0.125),              # issue 45 #6: inside the cube, no surface cell
    (((0.5,) * 3, (1.5,) * 3), 0.125),                # a corner
    (((0.5, 0.25, 0.5), (1.5, 1.0, 1.0)), 0.1875),    # two faces on the bounds' own
    (((2.0,) * 3, (3.0,) * 3), 0.0)])                 # outside
def test_bounds_cutting_the_mesh_add_up_to_the_volume_inside(bounds, want):
    g = libvox.voxelize(box((0, 0, 0), (1, 1, 1)), dims=8, bounds=bounds, fraction=True)
    fr = np.asarray(g.fractions)
    assert np.all((fr >= 0) & (fr <= 1))
    assert total_volume(g) == pytest.approx(want, abs=1e-15)
