// --batch over MPI ranks: the listed scenes handed out one at a time (work_queue.h); a bad scene is that scene's
// failure, not the rank's, so the queue goes on; rank 0 prints each failed scene's error in list order.
#include <mpi.h>

#include <atomic>
#include <chrono>

#include "batch.h"
#include "failures.h"
#include "gather.h"
#include "runs.h"
#include "vox/core/progress.h"
#include "work_queue.h"

namespace vox::mpi {

namespace {

using Clock = std::chrono::steady_clock;

// Voxelizes the scenes this rank is handed until none is left, each scene's outcome into mine.scenes. Collective.
void voxelizeScenes(const Options& opt, int rank, const std::vector<std::string>& scenes,
                    const std::vector<std::string>& outputs, Outcome& mine) {
  ProgressBar bar("voxelizing scenes", opt.common.quiet || rank != 0);
  std::atomic<uint64_t> done{0};
  runWorkQueue(MPI_COMM_WORLD, scenes.size(), [&](uint64_t i) {
    const auto t = Clock::now();
    std::string message;
    const int32_t code = capture([&] { voxelizeOne(opt, scenes[i], outputs[i]); }, message);
    mine.scenes.push_back({i, code, message});
    mine.seconds += std::chrono::duration<double>(Clock::now() - t).count();
    ++mine.items;
    bar.update(double(++done) / double(scenes.size()));
    return true;
  });
  bar.finish();
}

// Rank 0, once every rank reported: the list's or the folder's error (every rank saw the same), or each failed
// scene's. Returns the exit code.
int finishBatch(const Options& opt, const std::vector<Outcome>& all, size_t sceneCount) {
  if (all[0].code != kExitOk) {
    printError(all[0].message);
    return all[0].code;
  }
  const BatchSummary summary = summarizeBatch(all);
  for (const std::string& error : summary.errors) printError(error);
  if (!summary.errors.empty() && !opt.common.quiet)
    std::fprintf(stderr, "vox-voxelize-mpi: %zu of %zu scenes failed\n", summary.errors.size(), sceneCount);
  return summary.code;
}

}  // namespace

int runBatch(const Options& opt) {
  const auto start = Clock::now();
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  Outcome mine;
  std::vector<std::string> scenes, outputs;
  mine.code = capture(
      [&] {
        if (!opt.bricks.empty()) fail<UsageError>("--bricks cannot be combined with --batch");
        scenes = readBatchList(opt.batch);
        outputs = batchOutputs(opt.batch, scenes, opt.output);
        if (rank == 0) makeOutputFolder(opt.output);
      },
      mine.message);
  int anyFailed = mine.code;
  MPI_Allreduce(MPI_IN_PLACE, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (!anyFailed) voxelizeScenes(opt, rank, scenes, outputs, mine);
  mine.peakMb = peakMemoryMb();
  const std::vector<Outcome> all = gatherOutcomes(MPI_COMM_WORLD, mine);
  int code = kExitOk;
  if (rank == 0) {
    code = finishBatch(opt, all, scenes.size());
    if (opt.stats)
      std::fputs(rankStatsText(all, std::chrono::duration<double>(Clock::now() - start).count()).c_str(), stderr);
  }
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return code;
}

}  // namespace vox::mpi
