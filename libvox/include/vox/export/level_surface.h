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
  size_t cubes = 0;         // cubes of 8 cell centres with corners on both sides (those that make faces)
  size_t capTriangles = 0;  // triangles of cubes reaching beyond the grid (the cap on the grid's bounds)
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
//  - Sides: a band centre's from its distance; a centre outside the band takes the side of the band cell before it
//    in its row along x (else the one after it; a row without band cells takes a neighbouring row's); cells beyond
//    the grid are outside. Every cube of the grid padded by one cell whose corners are not all on one side is
//    marched, so the output is closed and manifold for any band. For a continuous field (a closed mesh) and
//    |level| <= largestSurfaceLevel, a centre outside the band is more than a cell diagonal beyond the level, so
//    only cubes with all 8 centres in the band make faces, besides the cap closing the surface on the grid's bounds
//    where it leaves the grid (vertices halfway between the last centre and the next one beyond). An open mesh's
//    sign jumps where its winding number crosses 1/2 (the caps of its holes); where that is farther than the band
//    from every triangle, the cap's faces cross cells outside the band, placed by those rows' nearest band cells.
//  - Vertices: one per lattice edge (axis, face diagonal or cube diagonal) whose ends lie on both sides, linearly
//    interpolated between band values, t = (level - d0) / (d1 - d0), clamped to [2^-10, 1 - 2^-10] of the edge so
//    that no two vertices coincide and no triangle has zero area even after float32 output; halfway along edges
//    with an end outside the band or beyond the grid. For a vertex on an edge of length L whose ends have
//    d0 < level <= d1 (continuous field), 1-Lipschitz distances give |d(vertex) - level| <=
//    max(t, 1 - t) (L - (d1 - d0)) + 2^-10 L < L <= D (the cell diagonal).
//  - Output: triangles (faceStart steps of 3), counter-clockwise seen from outside (normals point to increasing
//    distance), no colours; vertices ordered by lattice edge, faces by cube: the result does not depend on threads.
// Throws InputError when the grid has no distances ("... no signed distances: voxelize it with --sdf"), when |level|
// exceeds largestSurfaceLevel (the message gives the allowed range and the --sdf HALF that would allow `level`) or
// is not finite; LimitError beyond 2^32 - 1 vertices or triangles. `progress` (may be empty) is called with the
// fraction done; returning false throws Error("surface cancelled").
VoxelMesh extractLevelSurface(const Grid& grid, double level, LevelSurfaceStats* stats = nullptr,
                              const std::function<bool(double)>& progress = {});

}  // namespace vox
