// Voxelizing a scene into a grid set (issue 13): the sets stage, above io (the set's files, vox/io/grid_set.h) and
// voxelize (one brick at a time), so that neither reaches into the other. vox-voxelize --bricks runs writeGridSet;
// vox-voxelize-mpi hands writeBrick's bricks out over ranks.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/io/grid_set.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {

// Voxelizes brick `index` of the planned grid and, when it has occupied cells, writes its brick file. Returns its
// entry; occupied == 0 means nothing was written. `set` gives the plan, the brick counts and the scene file.
// Throws as voxelizeBrick and OutputError.
BrickEntry writeBrick(const std::string& setPath, const GridSetManifest& set, const Scene& scene, const Grid& plan,
                      const std::array<uint32_t, 3>& index, std::span<const uint32_t> candidates,
                      const VoxelizeOptions& options, VoxelizeStats* stats = nullptr);

// The whole job on one process: the output checked, plan, scene file, candidates, each brick voxelized and written
// before the next starts, the fill when `fill` is given (its report in `fillReport`), then the manifest, through a
// GridSetOutput (a failure or cancel leaves the old set whole). `progress` (may be empty)
// gets the fraction of bricks done. Returns the manifest written.
GridSetManifest writeGridSet(const std::string& setPath, const Scene& scene, const VoxelizeOptions& options,
                             const std::array<uint32_t, 3>& bricks, VoxelizeStats* stats = nullptr,
                             const FillOptions* fill = nullptr, FillReport* fillReport = nullptr);

}  // namespace vox
