#include "run_set.h"

#include <mutex>

#include "report.h"
#include "vox/core/error.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/sets/voxelize_set.h"

namespace vox::voxelize_tool {

int runSet(const Options& opt, const Scene& scene, VoxelizeOptions vo, std::chrono::steady_clock::time_point start) {
  ProgressBar bar("voxelizing bricks", opt.common.quiet);
  vo.progress = [&](double f) {
    bar.update(f);
    return true;
  };
  VoxelizeStats stats;
  GridSetManifest set;
  ProgressBar fillBar("filling", opt.common.quiet);
  std::once_flag bricksDone;  // the fill calls progress from worker threads
  FillOptions fo;
  fo.memoryLimitBytes = vo.memoryLimitBytes;
  fo.progress = [&](double f) {
    std::call_once(bricksDone, [&] { bar.finish(); });
    fillBar.update(f);
    return true;
  };
  FillReport report;
  try {
    set = writeGridSet(opt.output, scene, vo, {opt.bricks[0], opt.bricks[1], opt.bricks[2]}, &stats,
                       opt.fill ? &fo : nullptr, &report);
    bar.finish();
    fillBar.finish();
  } catch (const LimitError& e) {
    fail<LimitError>(opt.scene, ": ", e.what());
  } catch (const InputError& e) {
    fail<InputError>(opt.scene, ": ", e.what());
  }
  if (opt.fill) reportFill(opt, report);
  if (opt.stats)
    printSetStats(scene, set, stats, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return kExitOk;
}

}  // namespace vox::voxelize_tool
