// Bricks of a grid set (issue 13): how a grid's cells are split into boxes of whole cells, and which primitives
// each box needs. No I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox {

// Cells of brick b on an axis of n cells split into B bricks: [floor(n b / B), floor(n (b + 1) / B)). Every brick
// has at least one cell when 1 <= B <= n. Throws UsageError unless 1 <= bricks[a] <= dims[a] on every axis.
void checkBrickCounts(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks);
CellWindow brickWindow(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks,
                       const std::array<uint32_t, 3>& index);
// Linear brick number bx + BX (by + BY bz) and back.
uint64_t brickNumber(const std::array<uint32_t, 3>& bricks, const std::array<uint32_t, 3>& index);
std::array<uint32_t, 3> brickIndex(const std::array<uint32_t, 3>& bricks, uint64_t number);

// For every brick (by brickNumber), the ascending ids of the bounded primitives whose cell range meets it: the
// candidates voxelizeBrick needs. Throws LimitError (via memoryLimitBytes) before allocating when the lists would
// not fit.
std::vector<std::vector<uint32_t>> brickCandidates(const Scene& scene, const Grid& plan,
                                                   const std::array<uint32_t, 3>& bricks, uint64_t memoryLimitBytes);

// Appends `run` after sorted, non-overlapping runs, merging it with the last one when they touch.
void appendSolidRun(std::vector<CellRun>& runs, const CellRun& run);

// The solid runs of the whole grid (sorted, as Grid::solidRuns) split by brick: for each brick holding solid cells,
// ascending by brickNumber, the runs clipped to it, sorted and merged where they touch. Merging every brick's runs
// again (sort, appendSolidRun) gives back `runs` exactly.
std::vector<std::pair<uint64_t, std::vector<CellRun>>> splitRunsByBrick(std::span<const CellRun> runs,
                                                                        const std::array<uint32_t, 3>& dims,
                                                                        const std::array<uint32_t, 3>& bricks);

}  // namespace vox
