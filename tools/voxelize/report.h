// What vox-voxelize says on stderr besides errors: how the fill decided, and --stats as "name: value" lines.
#pragma once

#include "options.h"
#include "vox/core/scene.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/voxelize/fill.h"

namespace vox::voxelize_tool {

// How the fill decided is always said, unless --quiet (an open mesh once filled nothing, silently).
void reportFill(const Options& opt, const FillReport& report);

// --stats of a grid file: the scene's primitives, the grid, the voxelizer's counters and the times in seconds.
struct GridTimes {
  double read = 0, total = 0;
  WriteTimes write;
};
void printGridStats(const Scene& scene, const Grid& grid, const VoxelizeStats& stats, const GridTimes& times);

// --stats of a grid set: the scene's primitives, the set's plan and bricks, its totals over the written bricks.
void printSetStats(const Scene& scene, const GridSetManifest& set, const VoxelizeStats& stats, double totalSeconds);

}  // namespace vox::voxelize_tool
