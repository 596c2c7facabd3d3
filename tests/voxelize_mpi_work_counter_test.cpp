// Rank 0's work counter (tools/voxelize-mpi/work_counter.h), the part of the work queue that needs no MPI: every
// item handed out exactly once however many threads take, none after stop().
#include "voxelize-mpi/work_counter.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace vox::mpi {
namespace {

TEST(VoxelizeMpiWorkCounter, EachItemOnceAcrossThreads) {
  constexpr uint64_t kItems = 20000;
  WorkCounter counter(kItems);
  std::vector<std::vector<uint64_t>> taken(4);
  std::vector<std::thread> threads;
  for (auto& mine : taken)
    threads.emplace_back([&counter, &mine] {
      for (uint64_t i = counter.take(); i != kNoMoreItems; i = counter.take()) mine.push_back(i);
    });
  for (auto& t : threads) t.join();
  std::vector<int> seen(kItems, 0);
  for (const auto& mine : taken)
    for (size_t k = 0; k < mine.size(); ++k) {
      ASSERT_LT(mine[k], kItems);
      ++seen[mine[k]];
      // One counter: each taker sees its items ascending.
      if (k > 0) {
        EXPECT_LT(mine[k - 1], mine[k]);
      }
    }
  for (uint64_t i = 0; i < kItems; ++i) EXPECT_EQ(seen[i], 1) << i;
  EXPECT_EQ(counter.take(), kNoMoreItems);
}

TEST(VoxelizeMpiWorkCounter, NothingAfterStopOrWhenEmpty) {
  WorkCounter counter(10);
  EXPECT_EQ(counter.take(), 0u);
  EXPECT_EQ(counter.take(), 1u);
  counter.stop();
  EXPECT_EQ(counter.take(), kNoMoreItems);
  WorkCounter none(0);
  EXPECT_EQ(none.take(), kNoMoreItems);
}

}  // namespace
}  // namespace vox::mpi
