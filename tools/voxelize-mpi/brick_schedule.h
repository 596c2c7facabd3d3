// Which bricks of a grid set vox-voxelize-mpi hands out, and in what order. Every rank plans the same grid from the
// same scene, so all agree on the plan, the candidates and the order without sending them. No MPI here
// (tests/voxelize_mpi_brick_schedule_test.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox::mpi {

struct BrickSchedule {
  Grid plan;                                      // planGrid's grid, with outsidePrims under user bounds
  std::vector<std::vector<uint32_t>> candidates;  // per brick number: the primitives it needs (brickCandidates)
  std::vector<uint64_t> order;                    // the work items: brick numbers with candidates, most first
};

// The plan and candidates of `bricks` bricks for `scene`, as vox-voxelize --bricks makes them (writeGridSet). Throws
// UsageError for brick counts the grid cannot hold, LimitError when the lists outgrow options.memoryLimitBytes, and
// as planGrid. `order` is left empty (brickOrder, once every rank has started).
BrickSchedule planBricks(const Scene& scene, const VoxelizeOptions& options, const std::array<uint32_t, 3>& bricks);

// The bricks with candidates, those with the most first (ties: lower number first): a dense brick started last would
// keep every other rank waiting.
std::vector<uint64_t> brickOrder(const std::vector<std::vector<uint32_t>>& candidates);

}  // namespace vox::mpi
