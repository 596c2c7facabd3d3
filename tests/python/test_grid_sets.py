"""Grid.save(path, bricks=...) (issue 45, defects 4 and 5): the set holds the grid's own cells and solid runs, so it
loads back as the grid whatever made its solid cells; a grid with signed distances or volume fractions, which a set
cannot hold, is refused before anything is written; a refusal or a cancel leaves the old output whole."""
import os

import numpy as np
import pytest

import libvox
from conftest import assert_same_grid, box


def hollow_box():
    """The issue's input: a closed box with an inner box oriented inward (a closed cavity)."""
    outer, inner = box((0, 0, 0), (1, 1, 1)), box((0.3, 0.3, 0.3), (0.7, 0.7, 0.7), inward=True)
    return np.vstack([outer[0], inner[0]]), np.vstack([outer[1], inner[1] + 8])


def snapshot(folder):
    """Every file under `folder` with its bytes."""
    files = {}
    for root, _, names in os.walk(folder):
        for name in names:
            path = os.path.join(root, name)
            with open(path, "rb") as f:
                files[os.path.relpath(path, folder)] = f.read()
    return files


@pytest.mark.parametrize("old", ["grid file", "grid set"])
@pytest.mark.parametrize("what", ["fraction", "sdf"])
def test_bricks_of_a_grid_with_fractions_or_distances_are_refused_before_anything_is_written(tmp_path, old, what):
    args = {"fraction": True} if what == "fraction" else {"sdf": 2}
    g = libvox.voxelize(hollow_box(), resolution=16, fill=True, **args)
    assert g.fractions.size > 0 if what == "fraction" else g.sdf_half_width == 2
    path = tmp_path / "out.vgrid"
    previous = libvox.voxelize(box((0, 0, 0), (1, 1, 1)), resolution=8, fill=True)
    previous.save(path, **({"bricks": 2} if old == "grid set" else {}))
    before = snapshot(tmp_path)
    with pytest.raises(libvox.UsageError, match=r"^bricks: a grid set holds no signed distances or volume fractions"):
        g.save(path, bricks=2)
    assert snapshot(tmp_path) == before
    assert_same_grid(libvox.load(path), previous)
    g.save(path)  # without bricks, the single grid file holds them
    back = libvox.load(path)
    assert np.array_equal(back.fractions, g.fractions) and back.sdf_half_width == g.sdf_half_width


def test_a_bricked_save_loads_back_as_the_grid(tmp_path):
    """The fill of a hollow box (the cavity filled as enclosed), an open box (winding number), cells that are not
    cubes: the set is the grid, for bricks from one to one cell across (x and y)."""
    v, f = hollow_box()
    bv, bf = box((0, 0, 0), (1, 1, 1))
    wide = ((-0.2, -0.1, -0.15), (1.2, 1.1, 1.05))
    grids = [libvox.voxelize((v, f), resolution=16, fill=True),
             libvox.voxelize((bv, bf[:10]), dims=12, bounds=wide, fill=True),  # a face missing
             libvox.voxelize((v, f), dims=(9, 8, 7), bounds=wide, fill=True)]
    for g in grids:
        assert g.solid_count > 0
        for bricks in [1, 2, (3, 1, 2), (g.dims[0], g.dims[1], 1)]:
            path = tmp_path / "s.vgrid"
            g.save(path, bricks=bricks)
            assert_same_grid(libvox.load(path), g)


def test_a_cancelled_bricked_save_leaves_the_old_set_whole(tmp_path):
    """A progress callable that raises at its first call, or only at the fraction 1 (every brick written, the
    manifest not yet), cancels the save: the old set stays as it was and the new files are gone."""
    g = libvox.voxelize(hollow_box(), resolution=16, fill=True)
    path = tmp_path / "s.vgrid"
    old = libvox.voxelize(box((0, 0, 0), (1, 1, 1)), resolution=8, fill=True)
    old.save(path, bricks=(2, 2, 2))
    before = snapshot(tmp_path)
    for last in [0.0, 1.0]:
        def progress(fraction, last=last):
            if fraction >= last:
                raise RuntimeError("stop")

        with pytest.raises(RuntimeError, match="stop"):
            g.save(path, bricks=(2, 2, 2), progress=progress)
        assert snapshot(tmp_path) == before
    assert_same_grid(libvox.load(path), old)
