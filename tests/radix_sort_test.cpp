// The voxelizer's reference sort (voxelize/radix_sort.h) and the buffer sizing around it (issue 26): the sort of
// parts equals std::sort of their concatenation for every width and split, and a grid does not depend on how many
// threads made it (each thread's references are reserved from its share of the estimate: a thread that outgrows
// its share must still give the same grid).
#include "voxelize/radix_sort.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <random>

#include "test_util.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

TEST(RadixSort, PartsSortLikeStdSortOfTheirConcatenation) {
  std::mt19937_64 rng(7);
  for (int bits : {1, 11, 12, 22, 47, 64}) {
    for (size_t nParts : {size_t(1), size_t(3), size_t(8)}) {
      std::vector<std::vector<uint64_t>> parts(nParts);
      std::vector<uint64_t> all;
      const uint64_t mask = bits == 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
      for (size_t p = 0; p < nParts; ++p) {
        const size_t n = p == 1 ? 0 : size_t(rng() % 5000);  // an empty part among them
        for (size_t i = 0; i < n; ++i) parts[p].push_back(rng() & mask);
        all.insert(all.end(), parts[p].begin(), parts[p].end());
      }
      std::vector<std::span<const uint64_t>> spans(parts.begin(), parts.end());
      std::sort(all.begin(), all.end());
      // On one thread, and through the parallel path (top digit, then each bucket) whatever the size.
      for (const size_t parallelFrom : {kParallelSortFrom, size_t(0)}) {
        const auto [sorted, n] = radixSortParts(spans, bits, parallelFrom);
        ASSERT_EQ(n, all.size());
        EXPECT_TRUE(std::equal(all.begin(), all.end(), sorted.get()))
            << bits << " bits, " << nParts << " parts, parallel from " << parallelFrom;
      }
    }
  }
  const auto [none, n] = radixSortParts({}, 40);
  EXPECT_EQ(n, 0u);
}

TEST(RadixSort, LargeInputsOnTheParallelPath) {
  // Past kParallelSortFrom: blocks of the top-digit pass straddle parts, buckets large enough for LSD passes and
  // small enough for the comparison sort, keys crowded into a few buckets (a grid's references are).
  std::mt19937_64 rng(9);
  for (int bits : {20, 47, 64}) {
    std::vector<std::vector<uint64_t>> parts(3);
    std::vector<uint64_t> all;
    const uint64_t mask = bits == 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
    for (size_t p = 0; p < parts.size(); ++p) {
      const size_t count = 70000 + 30000 * p;
      for (size_t i = 0; i < count; ++i) {
        const uint64_t k = rng() & mask;
        parts[p].push_back(i % 3 == 0 ? k : k >> (bits / 2));  // two thirds in the lowest buckets
      }
      all.insert(all.end(), parts[p].begin(), parts[p].end());
    }
    std::vector<std::span<const uint64_t>> spans(parts.begin(), parts.end());
    const auto [sorted, n] = radixSortParts(spans, bits);
    std::sort(all.begin(), all.end());
    ASSERT_EQ(n, all.size());
    EXPECT_TRUE(std::equal(all.begin(), all.end(), sorted.get())) << bits << " bits";
  }
}

TEST(RadixSort, GridsDoNotDependOnTheThreadCount) {
  const Scene scene = testing::randomScene(11, 400, 5, -1, 2);
  for (const OverlapMethod method : {OverlapMethod::Exact, OverlapMethod::BBox}) {
    VoxelizeOptions o;
    o.method = method;
    o.dims = std::array<uint32_t, 3>{96, 80, 64};
    std::string first;
    for (int threads : {1, 2, 5, 16}) {
      tbb::task_arena arena(threads);
      const std::string bytes = arena.execute([&] { return encodeGridFile(scene, voxelizeScene(scene, o)); });
      if (first.empty()) first = bytes;
      EXPECT_EQ(bytes, first) << threads << " threads, method " << int(method);
    }
  }
}

}  // namespace
}  // namespace vox
