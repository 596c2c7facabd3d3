// The surface back from the field (issue 47): the level set d = LEVEL of a grid's signed-distance band as a closed,
// two-manifold, outward-oriented triangle mesh, for vox-export --surface and Grid.surface (docs/vox-export.md,
// "Surfaces from the distances"). Pure geometry over the band as stored (Grid::sdfKeys, sdfValues, sdfHalfWidth).
#pragma once

#include <cstddef>
#include <functional>

#include "vox/core/grid.h"
#include "vox/export/voxel_mesh.h"

namespace vox {

struct LevelSurfaceStats {
  size_t cubes = 0;         // cubes of 8 cell centres visited (all 8 in the band, or closing the grid's boundary)
  size_t capTriangles = 0;  // triangles of the closing cap on the grid's bounds (the level set leaving the grid)
  double seconds = 0;
};

// The largest |level| extractLevelSurface accepts for `grid` (world units): HALF * h - D, h the smallest cell edge
// and D the diagonal of a cell, so that every cube of centres the level crosses lies entirely in the band (a
// centre outside the band is more than D from the level, and distances are 1-Lipschitz). Negative when the band is
// too narrow for any level (HALF * h < D); 0 without a band.
double largestSurfaceLevel(const Grid& grid);

// The half-width (in smallest cell edges, as --sdf HALF) a band of `grid`'s cells needs for largestSurfaceLevel to
// reach |level|: at least 3 (the default band), a little more than (|level| + D) / h otherwise. Throws InputError
// when that exceeds 64 (the widest band --sdf stores), naming the largest level the grid's cells allow.
double surfaceHalfWidth(const Grid& grid, double level);

// The level set {p : d(p) = level} of the grid's signed distances (negative inside), by marching tetrahedra over the
// Freudenthal (Kuhn) triangulation of the lattice of cell centres: each cube of 8 centres is cut into the 6
// tetrahedra around its diagonal from the low to the high corner, the same split in every cube, so neighbouring
// cubes agree on each shared face and the level set of the piecewise-linear interpolant is a closed 2-manifold
// (no ambiguous case exists). A centre is inside when its distance is < level.
//  - Cubes: those whose 8 centres are all in the band; cubes with a centre outside it make no face (the level
//    cannot cross them: see largestSurfaceLevel). Cells beyond the grid count as outside, so where the level set
//    leaves the grid it is closed by a cap on the grid's bounds (its vertices lie on the bounds, halfway between
//    the last centre and the next one beyond); the sign of a boundary cell outside the band is that of the
//    nearest band cell in its row along x (or, for a row without band cells, of a neighbouring row's).
//  - Vertices: one per lattice edge (axis, face diagonal or cube diagonal) whose ends lie on both sides, linearly
//    interpolated, t = (level - d0) / (d1 - d0), clamped to [2^-10, 1 - 2^-10] of the edge so that no two vertices
//    coincide and no triangle has zero area even after float32 output. For a vertex on an edge of length L with
//    end values d0 < level <= d1, 1-Lipschitz distances give |d(vertex) - level| <= max(t, 1 - t) (L - (d1 - d0))
//    + 2^-10 L < L <= D (the cell diagonal); on a smooth surface the error is second order (see the docs).
//  - Output: triangles (faceStart steps of 3), counter-clockwise seen from outside (normals point to increasing
//    distance), no colours; vertices ordered by lattice edge, faces by cube: the result does not depend on threads.
// Throws InputError when the grid has no distances ("... no signed distances: voxelize with --sdf"), when |level|
// exceeds largestSurfaceLevel (the message gives the allowed range and the --sdf HALF that would allow `level`),
// when level is not finite, or when the band is inconsistent (the level crosses a cube with a centre outside the
// band, which no band libvox computes has); LimitError beyond 2^32 - 1 vertices. `progress` (may be empty) is
// called with the fraction done; returning false throws Error("surface cancelled").
VoxelMesh extractLevelSurface(const Grid& grid, double level, LevelSurfaceStats* stats = nullptr,
                              const std::function<bool(double)>& progress = {});

}  // namespace vox
