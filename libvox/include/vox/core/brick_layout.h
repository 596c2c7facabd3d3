// How a grid's cells split into bricks of whole cells (grid sets, issue 13): which cells a brick holds, how bricks
// are numbered, and solid runs cut at brick faces. Pure arithmetic on dims, in core because the voxelizer (one brick
// at a time), the set files (io/grid_set.h) and the set orchestration (sets/) all use it. No I/O.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "vox/core/grid.h"

namespace vox {

// A box of whole cells: first[a] <= i < end[a] on each axis a (a brick of a grid set).
struct CellWindow {
  std::array<uint32_t, 3> first{0, 0, 0};
  std::array<uint32_t, 3> end{1, 1, 1};
};

// Cells of brick b on an axis of n cells split into B bricks: [floor(n b / B), floor(n (b + 1) / B)). Every brick
// has at least one cell when 1 <= B <= n. Throws UsageError unless 1 <= bricks[a] <= dims[a] on every axis.
void checkBrickCounts(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks);
CellWindow brickWindow(const std::array<uint32_t, 3>& dims, const std::array<uint32_t, 3>& bricks,
                       const std::array<uint32_t, 3>& index);
// The brick holding cell c on an axis of n cells in B bricks: the largest b with floor(n b / B) <= c.
inline uint32_t brickOfCell(uint64_t c, uint64_t n, uint64_t B) { return uint32_t(((c + 1) * B - 1) / n); }
// Linear brick number bx + BX (by + BY bz) and back.
uint64_t brickNumber(const std::array<uint32_t, 3>& bricks, const std::array<uint32_t, 3>& index);
std::array<uint32_t, 3> brickIndex(const std::array<uint32_t, 3>& bricks, uint64_t number);

// Appends `run` after sorted, non-overlapping runs, merging it with the last one when they touch.
void appendSolidRun(std::vector<CellRun>& runs, const CellRun& run);

// The solid runs of the whole grid (sorted, as Grid::solidRuns) split by brick: for each brick holding solid cells,
// ascending by brickNumber, the runs clipped to it, sorted and merged where they touch. Merging every brick's runs
// again (sort, appendSolidRun) gives back `runs` exactly.
std::vector<std::pair<uint64_t, std::vector<CellRun>>> splitRunsByBrick(std::span<const CellRun> runs,
                                                                        const std::array<uint32_t, 3>& dims,
                                                                        const std::array<uint32_t, 3>& bricks);

}  // namespace vox
