"""libvox: exact voxelization and exact grid ray tracing for numpy.

    import libvox
    grid = libvox.voxelize("bunny.ply", resolution=128)      # or (vertices, faces), or a trimesh.Trimesh
    grid.dense().shape                                        # (128, 125, 99) np.bool_, indexed [i, j, k]
    grid.save("bunny.binvox")                                 # .vgrid, meshes, .binvox, .vox, .vdb
    t, prim, normal = grid.intersect(origins, directions)    # the same hits as brute force, bit for bit
    libvox.save_image("bunny.png", libvox.render(grid, size=(640, 480)))

Conventions: world coordinates float64; cell indices int32 [i, j, k] along x, y, z; cell (i, j, k) is the closed box
b_a(i) .. b_a(i+1) on each axis a, with b_a(i) = lo_a + (hi_a - lo_a) * i / n_a; its centre is the midpoint.
Errors: InputError (ValueError), UsageError (ValueError), LimitError (MemoryError), OSError for outputs, TypeError.
See docs/python.md of the libvox repository.
"""

from ._libvox import (
    Grid,
    InputError,
    LimitError,
    UsageError,
    __version__,
    load,
    render,
    save_image,
    sdf,
    surface,
    voxelize,
    voxelize_batch,
)



def _unpickle_grid(state):
    """The Grid of a pickle: Grid.__reduce__ names this function with the state (bytes of the grid file, source).

    A Python function, so that every pickle protocol finds it by name (pybind11's functions have no importable
    name); Grid.__new__ refuses, so no pickle stream can leave a Grid without its grid.
    """
    from . import _libvox
    return _libvox._grid_from_state(state)


__all__ = [
    "Grid",
    "InputError",
    "LimitError",
    "UsageError",
    "load",
    "render",
    "save_image",
    "sdf",
    "surface",
    "voxelize",
    "voxelize_batch",
]
