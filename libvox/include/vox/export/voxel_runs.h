// The voxels of a grid (occupied cells and solid cells, each once) as runs of consecutive keys, streamed in key
// order without expanding them: the voxel file formats (binvox, MagicaVoxel, OpenVDB) are written from these runs,
// so a filled 2048^3 grid with 10^9 solid cells costs memory in runs, not in voxels.
#pragma once

#include <cstdint>
#include <functional>

#include "vox/core/grid.h"

namespace vox {

// A run of voxels along x: cells (i0 .. i0 + count - 1, j, k), keys key .. key + count - 1.
struct VoxelRow {
  uint64_t key = 0;  // key of the first cell, cellKey(dims, i0, j, k)
  uint32_t i0 = 0, j = 0, k = 0;
  uint32_t count = 0;  // >= 1; i0 + count <= dims[0]
};

// Calls visit(first, end) for the union of grid.cellKeys and grid.solidRuns as maximal ranges [first, end) of
// consecutive keys, in increasing order (not cut at row ends, so a run over a billion rows is one call). Work is
// O(occupied cells + solid runs), whatever the number of cells. Throws as forEachVoxelRow.
void forEachVoxelInterval(const Grid& grid, const std::function<void(uint64_t first, uint64_t end)>& visit);

// Calls visit(row) for the union of grid.cellKeys and grid.solidRuns, in increasing key order, as maximal runs of
// consecutive keys cut at the ends of grid rows (so a run never leaves its (j, k) row). A cell that is both
// occupied and solid is visited once.
// Throws InputError when a cell key lies outside the grid or the keys are not sorted, or when the solid runs fail
// checkSolidRuns.
void forEachVoxelRow(const Grid& grid, const std::function<void(const VoxelRow&)>& visit);

// A source of voxel rows: each call hands every row to `visit` in increasing key order, as forEachVoxelRow does
// (a grid in memory, or a grid set read one layer of bricks at a time, which gives the same rows: a layer holds
// whole z planes, and rows never leave their plane). Writers that need several passes call it several times.
using VoxelRowSource = std::function<void(const std::function<void(const VoxelRow&)>& visit)>;
// The rows of a grid in memory (forEachVoxelRow) as a source; `grid` must outlive it.
VoxelRowSource voxelRows(const Grid& grid);

// What the writers' estimates start from, counted from the intervals in O(occupied cells + solid runs) without
// visiting a row: the distinct voxels (occupied or solid), and the rows forEachVoxelRow would visit.
struct VoxelTally {
  uint64_t voxels = 0;
  uint64_t rows = 0;
};
// Same checks as forEachVoxelRow.
VoxelTally tallyVoxels(const Grid& grid);

// Number of distinct voxels (occupied or solid): tallyVoxels(grid).voxels.
uint64_t countVoxels(const Grid& grid);

}  // namespace vox
