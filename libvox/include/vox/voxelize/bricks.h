// Bricks of a grid set (issue 13): which primitives each brick of a grid needs. The split into bricks itself is
// core's (brick_layout.h). No I/O.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vox/core/brick_layout.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox {

// For every brick (by brickNumber), the ascending ids of the bounded primitives whose cell range meets it: the
// candidates voxelizeBrick needs. Throws LimitError (via memoryLimitBytes) before allocating when the lists would
// not fit.
std::vector<std::vector<uint32_t>> brickCandidates(const Scene& scene, const Grid& plan,
                                                   const std::array<uint32_t, 3>& bricks, uint64_t memoryLimitBytes);

}  // namespace vox
