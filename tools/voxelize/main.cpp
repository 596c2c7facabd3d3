// vox-voxelize: scene file -> grid file (or, with --bricks, a grid set: run_set.cpp).
#include <chrono>

#include "distances.h"
#include "options.h"
#include "report.h"
#include "run_set.h"
#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"
#include "vox/io/grid_set.h"
#include "vox/voxelize/fill.h"
#include "vox/volume/fractions.h"

namespace {

using namespace vox;
using voxelize_tool::Options;

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Voxelizes (and fills, with --fill) with progress bars; what the scene asks for is named with the scene. `scene` is
// lent to the signed distances (addDistances) and given back as it was.
Grid voxelizeAndFill(const Options& opt, Scene& scene, VoxelizeOptions vo, VoxelizeStats& stats) {
  ProgressBar bar("voxelizing", opt.common.quiet);
  vo.progress = [&](double f) {
    bar.update(f);
    return true;
  };
  try {
    if (opt.fraction) checkVolumeFractionsPossible(scene, vo.method, vo.memoryLimitBytes);  // before any work
    checkNumericDomainOfPlan(scene, vo, opt.sdf.has_value(), opt.fraction);
    Grid grid = voxelizeScene(scene, vo, &stats);
    bar.finish();
    if (opt.fill) {
      ProgressBar fillBar("filling", opt.common.quiet);
      FillOptions fo;
      fo.memoryLimitBytes = vo.memoryLimitBytes;
      fo.progress = [&](double f) {
        fillBar.update(f);
        return true;
      };
      const FillReport report = fillSolid(grid, scene, opt.fraction ? fillForFractions(fo) : fo);
      fillBar.finish();
      voxelize_tool::reportFill(opt, report);
    }
    voxelize_tool::addDistances(opt, scene, vo.memoryLimitBytes, grid);
    return grid;
  } catch (const LimitError& e) {
    fail<LimitError>(opt.scene, ": ", e.what());
  } catch (const InputError& e) {
    fail<InputError>(opt.scene, ": ", e.what());
  }
}

int run(const Options& opt) {
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  VoxelizeOptions vo = voxelize_tool::voxelizeOptions(opt);

  // Before the scene is read: `-o scene.glb` would destroy the scene.
  checkOutputPath(opt.output, {opt.scene});
  voxelize_tool::checkDistanceFlags(opt);
  if (!opt.bricks.empty()) checkGridSetOutput(opt.output);  // "-o foo.bricks": refused before any work
  const std::optional<GridSetManifest> previousSet = opt.bricks.empty() ? previousGridSet(opt.output) : std::nullopt;
  Scene scene = loadScene(opt.scene);
  voxelize_tool::GridTimes times;
  times.read = secondsSince(start);
  if (!opt.common.quiet)
    for (const auto& w : scene.warnings) std::fputs(warningLine("vox-voxelize", w).c_str(), stderr);
  if (!opt.bricks.empty()) return voxelize_tool::runSet(opt, scene, vo, start);
  VoxelizeStats stats;
  vo = voxelize_tool::cubicCellsForDistances(opt, scene, vo);
  const Grid grid = voxelizeAndFill(opt, scene, vo, stats);
  if (!grid.outsidePrims.empty() && !opt.common.quiet)
    std::fputs(warningLine("vox-voxelize", opt.scene + ": " + std::to_string(grid.outsidePrims.size()) +
                                               " primitives stick out of the given bounds (traced separately)")
                   .c_str(),
               stderr);
  writeGridFile(opt.output, scene, grid, &times.write);
  if (previousSet) removeGridSetFiles(opt.output, *previousSet);  // a grid file replaced a set: its files go too
  times.total = secondsSince(start);
  if (opt.stats) voxelize_tool::printGridStats(scene, grid, stats, times);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (auto code = voxelize_tool::parseCommandLine(argc, argv, opt)) return *code;
  return runTool("vox-voxelize", [&] { return run(opt); });
}
