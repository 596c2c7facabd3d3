#include "distances.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/distance/sdf.h"
#include "vox/volume/fractions.h"

namespace vox::voxelize_tool {

void checkDistanceFlags(const Options& opt) {
  if (opt.sdf) checkSdfHalfWidth(*opt.sdf, "--sdf");
  if ((opt.sdf || opt.fraction) && !opt.bricks.empty())
    fail<UsageError>(
        "--sdf and --fraction write a single grid file; grid sets (--bricks) hold no distances or fractions");
}

VoxelizeOptions cubicCellsForDistances(const Options& opt, const Scene& scene, VoxelizeOptions vo) {
  return opt.sdf ? withCubicCells(scene, vo) : vo;
}

void addDistances(const Options& opt, Scene& scene, uint64_t memoryLimitBytes, Grid& grid) {
  if (opt.sdf) {
    if (!scene.planes.empty() && !opt.common.quiet)
      std::fputs(warningLine("vox-voxelize", opt.scene + ": " + std::to_string(scene.planes.size()) +
                                                 " planes are left out of the signed distances (unbounded)")
                     .c_str(),
                 stderr);
    ProgressBar bar("distances", opt.common.quiet);
    SdfOptions so;
    so.halfWidth = *opt.sdf;
    so.memoryLimitBytes = memoryLimitBytes;
    so.progress = [&](double f) {
      bar.update(f);
      return true;
    };
    storeSignedDistancesInPlace(grid, scene, so);
    bar.finish();
  }
  if (opt.fraction) {
    ProgressBar bar("fractions", opt.common.quiet);
    FractionOptions fo;
    fo.memoryLimitBytes = memoryLimitBytes;
    fo.progress = [&](double f) {
      bar.update(f);
      return true;
    };
    grid.fractions = volumeFractions(grid, scene, fo);
    bar.finish();
  }
}

}  // namespace vox::voxelize_tool
