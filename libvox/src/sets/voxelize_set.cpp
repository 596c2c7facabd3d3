// Voxelizing a scene into a grid set: the scene file first, then each brick voxelized and written before the next
// starts (so one brick's cells are in memory at a time), the fill's solid runs, the manifest last, all through a
// GridSetOutput (io/grid_set.h), which leaves the old set whole on a failure.
#include "vox/sets/voxelize_set.h"

#include "vox/core/error.h"
#include "vox/sets/fill_set.h"
#include "vox/voxelize/bricks.h"

namespace vox {

BrickEntry writeBrick(const std::string& setPath, const GridSetManifest& set, const Scene& scene, const Grid& plan,
                      const std::array<uint32_t, 3>& index, std::span<const uint32_t> candidates,
                      const VoxelizeOptions& options, VoxelizeStats* stats) {
  VoxelizeStats brickStats;
  const Grid grid =
      voxelizeBrick(scene, plan, brickWindow(plan.dims, set.bricks, index), candidates, options, &brickStats);
  if (stats) {
    stats->cellsTested += brickStats.cellsTested;
    stats->exactFallbacks += brickStats.exactFallbacks;
    stats->seconds += brickStats.seconds;
  }
  if (grid.occupiedCount() == 0) {
    BrickEntry e;
    e.index = index;
    return e;
  }
  return writeBrickFile(setPath, set, index, grid);
}

GridSetManifest writeGridSet(const std::string& setPath, const Scene& scene, const VoxelizeOptions& options,
                             const std::array<uint32_t, 3>& bricks, VoxelizeStats* stats, const FillOptions* fill,
                             FillReport* fillReport) {
  checkGridSetOutput(setPath);  // before any work
  Grid plan = planGrid(scene, options);
  checkBrickCounts(plan.dims, bricks);
  if (options.bounds) plan.outsidePrims = primitivesOutside(scene, plan);
  const auto candidates = brickCandidates(scene, plan, bricks, options.memoryLimitBytes);
  GridSetOutput output(setPath);
  GridSetManifest m{
      plan.bounds, plan.dims, plan.method, bricks, writeGridSetScene(setPath, output.folder(), scene, plan), {}};
  VoxelizeOptions brickOptions = options;
  brickOptions.progress = nullptr;
  for (uint64_t b = 0; b < candidates.size(); ++b) {
    if (options.progress && !options.progress(double(b) / double(candidates.size())))
      fail<Error>("voxelization cancelled");
    if (candidates[b].empty()) continue;
    const BrickEntry e = writeBrick(setPath, m, scene, plan, brickIndex(bricks, b), candidates[b], brickOptions, stats);
    if (e.occupied > 0) m.entries.push_back(e);
  }
  if (options.progress) options.progress(1.0);
  if (fill) {
    const FillReport report = fillGridSet(setPath, m, scene, *fill);
    if (fillReport) *fillReport = report;
  }
  output.commit(m);
  return m;
}

}  // namespace vox
