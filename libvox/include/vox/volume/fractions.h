// Volume fractions (DESIGN.md "Distance and volume", `--fraction`): for each occupied cell of a grid, the part of its
// closed box inside the scene's solid. Exact for closed, consistently oriented triangle meshes (the divergence
// theorem over the triangles clipped to the cell, the cell's high-x face and one of that face's edges, every
// inside/outside decision an exact predicate); balls to 1e-12 of the cell volume. Other solids are refused.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/voxelize/fill.h"

namespace vox {

struct FractionOptions {
  uint64_t memoryLimitBytes = 16ull << 30;  // scratch beyond this throws LimitError, before allocating
  // Called with a fraction in [0, 1], possibly from worker threads, at least every 0.1 s of work; return false to
  // cancel (throws vox::Error "... cancelled").
  std::function<bool(double)> progress;
};

// For occupied cell c (the order of grid.cellKeys), the volume of the intersection of its closed box (cellBox) with
// the solid, divided by the box's volume: a number in [0, 1]. The solid is the union of
//  - the region a closed triangle mesh bounds (every edge used as often in one direction as in the other after
//    welding vertices at equal positions, so the winding number is an integer; it must be 0 or 1 everywhere, or 0
//    or -1 for a mesh oriented inward): the result is exact up to floating-point rounding in the integrals, whose
//    effect is below 1e-12 of the cell volume for triangles up to 1000 cells wide (docs in fractions.cpp; tested);
//    the inside/outside decisions, including points exactly on the surface, are exact and consistent, so a surface
//    lying on cell planes costs no accuracy;
//  - balls (Sphere with an identity transform, or a rotation times a uniform scale plus a translation): the volume
//    of box and ball by quadrature of a closed-form cross-section, to 1e-12 of the cell volume.
// A cell the solids cover partly, and a cell of the mesh that a ball also reaches, must not hold two overlapping
// solids: two balls that overlap in a cell, or a ball in a cell of the mesh or inside it, are refused.
// Inputs: `grid` voxelized from `scene` by a conservative method (exact, sat or bbox: every triangle meeting a cell
// is among its primitives); grid.outsidePrims lists the triangles sticking out of user bounds. World space.
// Cells outside the occupied ones are not reported: fillSolid's solid cells are wholly inside (fraction 1).
// Work is spread over the caller's TBB arena; the result does not depend on the thread count.
// Throws UsageError, with one line saying why and what works instead, for planes, ellipsoids, open meshes,
// inconsistently oriented or self-overlapping meshes, overlapping solids and a `center` grid; LimitError when the
// scratch memory (about 80 bytes per cell-primitive reference) exceeds options.memoryLimitBytes; vox::Error when
// cancelled.
// The refusals volumeFractions makes before any cell (planes, ellipsoids, a `center` method, open or inconsistently
// oriented meshes), for tools to check before voxelizing. Throws UsageError, or LimitError when the check itself
// would need more than memoryLimitBytes.
void checkVolumeFractionsPossible(const Scene& scene, OverlapMethod method, uint64_t memoryLimitBytes);

// The fill whose solid cells agree with the fractions: the winding number decides every empty run, so a closed
// cavity (an inner shell oriented inward, w = 0) stays empty as the fractions count it, where the flood fill's
// Enclosed rule would fill it. `options` otherwise unchanged.
FillOptions fillForFractions(FillOptions options);

std::vector<double> volumeFractions(const Grid& grid, const Scene& scene, const FractionOptions& options = {});

}  // namespace vox
