// SCENE --bricks over MPI ranks: every rank plans the same grid from the same scene; bricks with the most candidates
// go first (brick_schedule.h), one at a time (work_queue.h); rank 0 gathers what each rank wrote (rank_protocol.h),
// runs the fill over the written bricks and writes the manifest last.
#include <mpi.h>

#include <atomic>
#include <chrono>
#include <memory>

#include "brick_schedule.h"
#include "broadcast.h"
#include "failures.h"
#include "gather.h"
#include "runs.h"
#include "vox/core/progress.h"
#include "vox/import/import.h"
#include "vox/io/atomic_file.h"
#include "vox/sets/fill_set.h"
#include "vox/sets/voxelize_set.h"
#include "work_queue.h"

namespace vox::mpi {

namespace {

using Clock = std::chrono::steady_clock;

// What one rank holds of the set being written.
struct SetRun {
  explicit SetRun(const Options& options)
      : opt(options), bricks{options.bricks[0], options.bricks[1], options.bricks[2]}, vo(voxelizeOptions(options)) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  }

  const Options& opt;
  int rank = 0;
  const std::array<uint32_t, 3> bricks;
  const VoxelizeOptions vo;
  Scene scene;
  BrickSchedule schedule;
  GridSetManifest set;
  std::unique_ptr<GridSetOutput> output;  // rank 0 makes the set's generation folder; the others register it
  Outcome mine;
};

// Reads the scene, plans the bricks and starts the set; the first failure goes into run.mine. Collective.
void startSet(SetRun& run) {
  const Options& opt = run.opt;
  run.mine.code = capture(
      [&] {
        checkOutputPath(opt.output, {opt.scene});
        checkGridSetOutput(opt.output);
        run.scene = loadScene(opt.scene);
        namingScene(opt.scene, [&] { run.schedule = planBricks(run.scene, run.vo, run.bricks); });
        if (run.rank == 0) run.output = std::make_unique<GridSetOutput>(opt.output);
      },
      run.mine.message);
  const std::string folder = broadcastString(MPI_COMM_WORLD, run.output ? run.output->folder() : std::string());
  if (run.mine.code != kExitOk) return;
  run.mine.code = capture(
      [&] {
        if (folder.empty()) fail<Error>("rank 0 could not start the set");
        if (run.rank != 0) run.output = std::make_unique<GridSetOutput>(opt.output, folder);
        // Every rank encodes the scene file to know its checksum (the bricks name it); rank 0 writes it.
        const Grid& plan = run.schedule.plan;
        run.set = {plan.bounds,
                   plan.dims,
                   plan.method,
                   run.bricks,
                   writeGridSetScene(opt.output, folder, run.scene, plan, run.rank == 0),
                   {}};
        run.schedule.order = brickOrder(run.schedule.candidates);
      },
      run.mine.message);
}

// Voxelizes and writes the bricks this rank is handed until none is left or one fails. Collective.
void writeBricks(SetRun& run) {
  const Options& opt = run.opt;
  const BrickSchedule& s = run.schedule;
  Outcome& mine = run.mine;
  ProgressBar bar("voxelizing bricks", opt.common.quiet || run.rank != 0);
  std::atomic<uint64_t> done{0};
  runWorkQueue(MPI_COMM_WORLD, s.order.size(), [&](uint64_t item) {
    const auto t = Clock::now();
    mine.code = capture(
        [&] {
          namingScene(opt.scene, [&] {
            const uint64_t b = s.order[item];
            mine.bricks.push_back(
                writeBrick(opt.output, run.set, run.scene, s.plan, brickIndex(run.bricks, b), s.candidates[b], run.vo));
          });
        },
        mine.message);
    mine.seconds += std::chrono::duration<double>(Clock::now() - t).count();
    ++mine.items;
    bar.update(double(++done) / double(s.order.size()));  // rank 0's own share: a rough bar
    return mine.code == kExitOk;
  });
  bar.finish();
}

// Rank 0, once every rank reported: the first failure printed, or the fill over the written bricks (it needs every
// brick's cells) and the manifest, then the replaced set's files removed. Returns the exit code.
int finishSet(SetRun& run, const std::vector<Outcome>& all) {
  const Options& opt = run.opt;
  std::string message;
  int code = setFailure(all, message);
  if (code == kExitOk)
    code = capture(
        [&] {
          GridSetManifest m = mergeBrickEntries(run.set, all);
          if (opt.fill)
            namingScene(opt.scene, [&] {
              const FillReport report =
                  fillGridSet(opt.output, m, run.scene, FillOptions{run.vo.memoryLimitBytes, {}, {}, false});
              if (!opt.common.quiet) std::fprintf(stderr, "vox-voxelize-mpi: fill: %s\n", describeFill(report).c_str());
            });
          run.output->commit(m);
        },
        message);
  if (code != kExitOk) printError(message);
  return code;
}

}  // namespace

int runSet(const Options& opt) {
  const auto start = Clock::now();
  SetRun run(opt);
  startSet(run);
  int anyFailed = run.mine.code;
  // Also the barrier that makes the brick folder exist before any rank writes into it.
  MPI_Allreduce(MPI_IN_PLACE, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (!anyFailed) writeBricks(run);
  std::vector<uint64_t>().swap(run.schedule.order);
  std::vector<std::vector<uint32_t>>().swap(run.schedule.candidates);
  run.mine.peakMb = peakMemoryMb();
  const std::vector<Outcome> all = gatherOutcomes(MPI_COMM_WORLD, run.mine);
  int code = kExitOk;
  if (run.rank == 0) {
    code = finishSet(run, all);
    if (opt.stats)
      std::fputs(rankStatsText(all, std::chrono::duration<double>(Clock::now() - start).count()).c_str(), stderr);
  }
  MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return code;
}

}  // namespace vox::mpi
