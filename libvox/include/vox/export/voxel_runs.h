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

// Number of distinct voxels (occupied or solid), counted from the runs. Same checks as forEachVoxelRow.
uint64_t countVoxels(const Grid& grid);

}  // namespace vox
