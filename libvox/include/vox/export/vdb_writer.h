// OpenVDB .vdb output of a grid's voxels, for Blender (volume objects), Houdini and other volume tools. OpenVDB
// itself stays in vdb_writer.cpp (the bridge); this header has no OpenVDB type.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>

#include "vox/core/grid.h"

namespace vox {

struct VdbStats {
  uint64_t activeVoxels = 0;  // active voxels of `density`: the grid's occupied and solid cells
  uint64_t leafNodes = 0;     // of `density`, after pruning (uniform 8^3 blocks become tiles)
};

// Writes `grid` as an OpenVDB file (OpenVDB 10, the library's default compression) holding two grids:
//  - `density` (FloatGrid, class fog volume): 1 in every occupied and solid cell, active there, 0 and inactive
//    elsewhere; uniform blocks are stored as tiles, so a filled interior costs little;
//  - `count` (FloatGrid, a float so that pyopenvdb reads the file): the number of primitives held by each occupied
//    cell (solid-only cells are not in it).
// With volume fractions (--fraction), `density` holds each occupied cell's fraction instead of 1. With distances
// (--sdf), a third grid `surface`: an OpenVDB level set (class level set, background HALF x voxel size, the band's
// signed distances as floats, inactive voxels signed by OpenVDB's flood fill); it needs cubic cells (UsageError).
// All carry the grid's exact per-axis voxel transform (a ScaleTranslateMap): index (i, j, k) is the centre of cell
// (i, j, k), world = lo + (index + 0.5) * (hi - lo) / n on each axis, so non-cubic cells keep their shape.
// Memory grows with the occupied cells and the solid runs' surface, not with the solid volume: the solid interior
// is built 8 layers of z at a time and pruned into tiles before the next layer.
// Throws InputError for an inconsistent grid; write errors are the stream's.
VdbStats writeVdb(std::ostream& out, const Grid& grid, const std::function<void(double)>& progress = {});

}  // namespace vox
