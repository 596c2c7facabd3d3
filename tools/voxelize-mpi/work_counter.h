// Rank 0's dispenser of work items for vox-voxelize-mpi: one counter that its own main thread and the helper thread
// answering the other ranks both take from (work_queue.h). No MPI here (tests/voxelize_mpi_work_counter_test.cpp).
#pragma once

#include <atomic>
#include <cstdint>

namespace vox::mpi {

inline constexpr uint64_t kNoMoreItems = ~uint64_t(0);

class WorkCounter {
 public:
  explicit WorkCounter(uint64_t count) : count_(count) {}
  // The next item of [0, count), each handed out once; kNoMoreItems once all are taken or after stop(). Thread-safe.
  uint64_t take() {
    if (stop_.load()) return kNoMoreItems;
    const uint64_t i = next_.fetch_add(1);
    return i < count_ ? i : kNoMoreItems;
  }
  // A rank failed: a failing rank fails the run, so the rest is not worth doing. Thread-safe.
  void stop() { stop_ = true; }

 private:
  const uint64_t count_;
  std::atomic<uint64_t> next_{0};
  std::atomic<bool> stop_{false};
};

}  // namespace vox::mpi
