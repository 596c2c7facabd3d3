// Inside or outside, for the centres of the occupied cells: the signs of --sdf and libvox.sdf there (DESIGN.md
// "Distance and volume": inside as --fill decides it), where the fill's flood cannot reach.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

// For each occupied cell (cellKeys order): whether its centre lies inside InsideTest's solid: inside a sphere or
// ellipsoid, or where the triangles' generalized winding number has magnitude at least kWindingThreshold.
//
// How: the mesh closed by the caps of its holes (openBoundaries) has an integer winding number k, and the mesh's
// own is w = k - s, s the caps' (none for a closed, consistently oriented mesh: w = k). k at a centre is the signed
// count of the crossings of its row's line (along x) before it, each decided exactly: the line against the
// triangle's edges by orient2d with the line perturbed symbolically (so an edge or vertex on the line counts once),
// the centre against the triangle's plane by orient3d. Only the triangles the row's cells hold can cross it there.
// s comes from the caps' winding tree, recomputed more closely near the threshold, as the fill does. A `center`
// grid (whose cells do not hold every triangle they meet), primitives outside the grid, or more than 64 holes (a
// soup) fall back to InsideTest at each centre.
//
// `progress` as DistanceQueryOptions::progress; throws vox::Error "... cancelled" when it returns false.
std::vector<uint8_t> occupiedCentresInside(const Grid& grid, const Scene& scene,
                                           const std::function<bool(double)>& progress = {});

}  // namespace vox
