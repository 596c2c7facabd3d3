// Solid fill (DESIGN.md "Solid fill"): marks the empty cells enclosed by occupied cells as solid.
#pragma once

#include <cstdint>

#include "vox/core/grid.h"

namespace vox {

// Fills grid.solidRuns with every empty cell that no 6-connected path of empty cells joins to the outside of the
// grid. An exact (conservative) voxelization of a closed surface leaves no such path through the surface, so these
// are exactly the empty cells inside closed surfaces; an open surface encloses nothing. Needs one bit per grid cell
// of scratch memory: throws LimitError when that exceeds `memoryLimitBytes`.
void fillSolid(Grid& grid, uint64_t memoryLimitBytes);

}  // namespace vox
