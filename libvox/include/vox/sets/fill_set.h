// --fill over a grid set (issue 13): the single grid's fill, decided from the set's bricks in memory bounded by a
// layer of bricks. The sets stage, above io (the set's files) and voxelize (SlabFill).
#pragma once

#include <string>

#include "vox/core/scene.h"
#include "vox/io/grid_set.h"
#include "vox/voxelize/fill.h"

namespace vox {

// --fill for a set whose bricks are written, in memory bounded by a brick rather than the grid: fills the set's
// occupied cells in slabs of whole planes (SlabFill, options.slabCells cells a slab), so that the solid cells are
// the single grid's, run for run. Reads the bricks one layer (bz) at a time, twice, keeping a layer's cell keys
// delta-coded (1 to 2 bytes a cell of a surface) and one slab's keys and scratch. After a layer's second reading,
// its solid runs are split by brick and the bricks holding solid cells rewritten (new ones written for bricks
// holding only solid cells). Updates set.entries (ascending). Throws as fillSolid, InputError for a corrupt brick,
// OutputError.
FillReport fillGridSet(const std::string& setPath, GridSetManifest& set, const Scene& scene,
                       const FillOptions& options);

}  // namespace vox
