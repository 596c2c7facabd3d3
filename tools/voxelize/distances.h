// vox-voxelize --sdf and --fraction: the signed distance band and the volume fractions added to a voxelized grid.
#pragma once

#include "options.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox::voxelize_tool {

// Checks the flags before any work: --sdf's half-width, and neither flag with --bricks (grid sets hold no
// distances).
// Throws UsageError.
void checkDistanceFlags(const Options& opt);

// With --sdf and --res, and no --bounds: the options with bounds grown about the scene's (by less than a cell on
// each shorter axis) so that the cells are exactly cubic, as an OpenVDB level set needs them (vox-export .vdb).
// `vo` unchanged otherwise.
VoxelizeOptions cubicCellsForDistances(const Options& opt, const Scene& scene, VoxelizeOptions vo);

// With --sdf: stores the band in `grid` (storeSignedDistancesInPlace: `scene` is lent and given back as it was),
// with a progress bar and a warning for planes. With --fraction (which implies --fill): the occupied cells' volume
// fractions (volumeFractions).
void addDistances(const Options& opt, Scene& scene, uint64_t memoryLimitBytes, Grid& grid);

}  // namespace vox::voxelize_tool
