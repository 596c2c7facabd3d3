#include "distances.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/distance/sdf.h"
#include "vox/voxelize/fill.h"

namespace vox::voxelize_tool {

void checkDistanceFlags(const Options& opt) {
  if (opt.sdf) checkSdfHalfWidth(*opt.sdf, "--sdf");
  if ((opt.sdf || opt.fraction) && !opt.bricks.empty())
    fail<UsageError>("--sdf and --fraction write a single grid file; grid sets (--bricks) hold no distances");
}

VoxelizeOptions cubicCellsForDistances(const Options& opt, const Scene& scene, VoxelizeOptions vo) {
  if (!opt.sdf || opt.resolution == 0 || !opt.bounds.empty()) return vo;
  const Grid plan = planGrid(scene, vo);
  double cell = 0;
  for (int a = 0; a < 3; ++a) cell = std::max(cell, (plan.bounds.hi[a] - plan.bounds.lo[a]) / opt.resolution);
  Box cubic;
  for (int a = 0; a < 3; ++a) {
    const double extent = plan.bounds.hi[a] - plan.bounds.lo[a];
    const double n = std::max(1.0, std::ceil(extent / cell - 1e-9));
    const double centre = 0.5 * (plan.bounds.lo[a] + plan.bounds.hi[a]);
    cubic.lo.at(a) = centre - 0.5 * n * cell;
    cubic.hi.at(a) = cubic.lo[a] + n * cell;
  }
  vo.bounds = cubic;
  return vo;
}

void addDistances(const Options& opt, const Scene& scene, uint64_t memoryLimitBytes, Grid& grid) {
  if (!opt.sdf && !opt.fraction) return;
  // The sign of the band's empty cells and the cells wholly inside come from the fill; without --fill it runs on
  // the side and its runs are not stored.
  std::vector<CellRun> keptRuns;
  if (!opt.fill) {
    ProgressBar bar("filling", opt.common.quiet);
    FillOptions fo;
    fo.memoryLimitBytes = memoryLimitBytes;
    fo.progress = [&](double f) {
      bar.update(f);
      return true;
    };
    fillSolid(grid, scene, fo);
    bar.finish();
  }
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
    SdfBand band = signedDistanceBand(grid, scene, so);
    bar.finish();
    grid.sdfHalfWidth = *opt.sdf;
    grid.sdfKeys = std::move(band.keys);
    grid.sdfValues = std::move(band.values);
  }
  if (opt.fraction) fail<UsageError>("--fraction is not available in this build yet");
  if (!opt.fill) grid.solidRuns = std::move(keptRuns);
}

}  // namespace vox::voxelize_tool
