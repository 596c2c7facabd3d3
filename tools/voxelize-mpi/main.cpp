// vox-voxelize-mpi: vox-voxelize over Open MPI ranks. A grid set's bricks (run_set.cpp), or a batch of scenes
// (run_batch.cpp), are handed out one at a time (work_queue.h); every rank reads the scene itself and writes its own
// files; rank 0 gathers what each rank did (rank_protocol.h), prints the one error of a failed run (or each failed
// scene of a batch) and writes the manifest last.
#include <mpi.h>

#include <algorithm>
#include <optional>
#include <thread>

#include "options.h"
#include "vox/core/tool.h"
#include "runs.h"

namespace {

// Default threads per rank: the node's cores shared by the ranks on it (two ranks on two cores: one thread each).
unsigned defaultThreads() {
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &local);
  int localRanks = 1;
  MPI_Comm_size(local, &localRanks);
  MPI_Comm_free(&local);
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  return std::max(1u, cores / unsigned(std::max(1, localRanks)));
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  vox::mpi::Options opt;
  const std::optional<int> early = vox::mpi::parseOnEveryRank(rank, argc, argv, opt);
  int code = early.value_or(0);
  if (!early) {
    auto threads = vox::cli::limitThreads(opt.common.threads ? opt.common.threads : defaultThreads());
    if (provided < MPI_THREAD_SERIALIZED) {
      if (rank == 0) std::fprintf(stderr, "vox-voxelize-mpi: error: this MPI library lacks MPI_THREAD_SERIALIZED\n");
      code = vox::kExitUsage;
    } else {
      code = opt.batch.empty() ? vox::mpi::runSet(opt) : vox::mpi::runBatch(opt);
    }
  }
  MPI_Finalize();
  return code;
}
