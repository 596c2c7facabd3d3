// vox-voxelize --bricks: the grid set of docs/grid-format.md, brick after brick, then the fill over the bricks' cells.
#pragma once

#include <chrono>

#include "options.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox::voxelize_tool {

// Writes the set of `scene` at opt.output with progress bars, the fill's report and --stats (times from `start`).
// Returns the exit code; throws as writeGridSet, with the scene named in what the scene asks for.
int runSet(const Options& opt, const Scene& scene, VoxelizeOptions vo, std::chrono::steady_clock::time_point start);

}  // namespace vox::voxelize_tool
