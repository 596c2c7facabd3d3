// Dynamic assignment of work items over MPI ranks for vox-voxelize-mpi. Rank 0 hands out item numbers from one
// counter: its own main thread takes them directly, a helper thread answers the other ranks' requests. Surface
// density varies, so items are taken one at a time as ranks finish, not split in advance.
#pragma once

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <thread>

#include "work_counter.h"

namespace vox::mpi {

inline constexpr int kTagRequest = 701;
inline constexpr int kTagItem = 702;

// Runs work(i) for items i taken from [0, count) until none is left. work returns false after a failure: the rank
// then stops, and every rank is handed no more items (a failing rank fails the run, so the rest is not worth doing).
// Collective over `comm`. Needs MPI_THREAD_SERIALIZED: while the helper thread calls MPI, rank 0's main thread
// does not.
inline void runWorkQueue(MPI_Comm comm, uint64_t count, const std::function<bool(uint64_t)>& work) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (rank == 0) {
    WorkCounter counter(count);
    std::thread helper;
    if (size > 1)
      helper = std::thread([&] {
        int open = size - 1;  // ranks not yet told that the work is done
        while (open > 0) {
          int flag = 0;
          MPI_Status status;
          MPI_Iprobe(MPI_ANY_SOURCE, kTagRequest, comm, &flag, &status);
          if (!flag) {
            // Polling, not a blocking receive: Open MPI spins in MPI_Recv, which would take a core from the work.
            std::this_thread::sleep_for(std::chrono::microseconds(200));
            continue;
          }
          int failed = 0;
          MPI_Recv(&failed, 1, MPI_INT, status.MPI_SOURCE, kTagRequest, comm, MPI_STATUS_IGNORE);
          if (failed) counter.stop();
          const uint64_t item = counter.take();
          MPI_Send(&item, 1, MPI_UINT64_T, status.MPI_SOURCE, kTagItem, comm);
          if (item == kNoMoreItems) --open;
        }
      });
    for (uint64_t i = counter.take(); i != kNoMoreItems; i = counter.take())
      if (!work(i)) counter.stop();
    if (helper.joinable()) helper.join();
    return;
  }
  int failed = 0;
  for (;;) {
    MPI_Send(&failed, 1, MPI_INT, 0, kTagRequest, comm);
    uint64_t item = kNoMoreItems;
    MPI_Recv(&item, 1, MPI_UINT64_T, 0, kTagItem, comm, MPI_STATUS_IGNORE);
    if (item == kNoMoreItems) return;
    if (!failed && !work(item)) failed = 1;
  }
}

}  // namespace vox::mpi
