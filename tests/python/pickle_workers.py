"""Functions the process pools of test_pickle.py run in their worker processes (spawned workers import them by name,
so they live in a module of their own, which imports nothing but libvox and numpy)."""

import pickle

import numpy as np

import libvox


def voxelize(path, resolution, fill):
    """A grid made in the worker, sent back pickled."""
    return libvox.voxelize(path, resolution=resolution, fill=fill)


def describe(grid):
    """What the worker sees of a grid the parent sent it: its arrays and its grid file bytes."""
    offsets, ids = grid.cell_primitives
    return {
        "dense": grid.dense(),
        "indices": grid.indices,
        "offsets": np.array(offsets),
        "ids": np.array(ids),
        "solid": grid.solid_indices,
        "bounds": grid.bounds,
        "state": grid.__getstate__(),
    }


def round_trip(grid):
    """The grid as the worker got it, sent back (parent -> worker -> parent)."""
    return pickle.loads(pickle.dumps(grid))
