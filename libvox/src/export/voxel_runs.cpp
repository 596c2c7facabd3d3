// Voxel runs (voxel_runs.h): a merge of the sorted occupied keys with the sorted solid runs.
#include "vox/export/voxel_runs.h"

#include <algorithm>

#include "vox/core/error.h"

namespace vox {

namespace {

constexpr uint32_t kMaxDim = uint32_t(1) << 21;

// Cuts the key range [first, end) at row ends and reports each piece.
void emitRows(const Grid& grid, uint64_t first, uint64_t end, const std::function<void(const VoxelRow&)>& visit) {
  const uint64_t nx = grid.dims[0];
  while (first < end) {
    const uint64_t row = first / nx;
    const uint64_t rowEnd = std::min(end, (row + 1) * nx);
    VoxelRow r;
    r.key = first;
    r.i0 = uint32_t(first - row * nx);
    r.j = uint32_t(row % grid.dims[1]);
    r.k = uint32_t(row / grid.dims[1]);
    r.count = uint32_t(rowEnd - first);
    visit(r);
    first = rowEnd;
  }
}

}  // namespace

void forEachVoxelInterval(const Grid& grid, const std::function<void(uint64_t first, uint64_t end)>& visit) {
  // Every grid libvox makes or reads has 1..2^21 cells per axis (docs/grid-format.md), so keys stay below 2^63 and
  // cellCount() cannot wrap; a grid built in memory by other means is held to the same.
  for (uint32_t n : grid.dims)
    if (n == 0 || n > kMaxDim) fail<InputError>("grid: dimension ", n, " outside 1..2^21");
  const uint64_t cells = grid.cellCount();
  checkSolidRuns(grid.solidRuns, cells, "grid");
  const HugeVector<uint64_t>& keys = grid.cellKeys;
  size_t a = 0, b = 0;
  bool open = false;
  uint64_t first = 0, end = 0;  // the run being grown, [first, end)
  while (a < keys.size() || b < grid.solidRuns.size()) {
    uint64_t start, stop;
    if (b == grid.solidRuns.size() || (a < keys.size() && keys[a] < grid.solidRuns[b].first)) {
      start = keys[a];
      if (start >= cells) fail<InputError>("grid: cell key ", start, " outside the grid");
      if (a > 0 && start <= keys[a - 1]) fail<InputError>("grid: cell keys not sorted at index ", a);
      stop = start + 1;
      ++a;
    } else {
      start = grid.solidRuns[b].first;
      stop = start + grid.solidRuns[b].count;
      ++b;
    }
    if (open && start <= end) {
      end = std::max(end, stop);
      continue;
    }
    if (open) visit(first, end);
    first = start;
    end = stop;
    open = true;
  }
  if (open) visit(first, end);
}

void forEachVoxelRow(const Grid& grid, const std::function<void(const VoxelRow&)>& visit) {
  forEachVoxelInterval(grid, [&](uint64_t first, uint64_t end) { emitRows(grid, first, end, visit); });
}

VoxelRowSource voxelRows(const Grid& grid) {
  return [&grid](const std::function<void(const VoxelRow&)>& visit) { forEachVoxelRow(grid, visit); };
}

VoxelTally tallyVoxels(const Grid& grid) {
  // Keys are below cellCount() <= 2^63 (dims at most 2^21), so neither sum can wrap.
  const uint64_t nx = grid.dims[0];
  VoxelTally t;
  forEachVoxelInterval(grid, [&](uint64_t first, uint64_t end) {
    t.voxels += end - first;
    t.rows += (end - 1) / nx - first / nx + 1;
  });
  return t;
}

uint64_t countVoxels(const Grid& grid) { return tallyVoxels(grid).voxels; }

}  // namespace vox
