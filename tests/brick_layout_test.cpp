// The split of a grid into bricks (brick_layout.h): windows tile each axis, numbers round-trip, solid runs cut at
// brick faces merge back exactly.
#include "vox/core/brick_layout.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "vox/core/error.h"

namespace vox {
namespace {

TEST(BrickLayout, CoversEveryCellOnce) {
  for (uint32_t n : {1u, 2u, 7u, 100u})
    for (uint32_t B = 1; B <= std::min(n, 9u); ++B) {
      uint32_t next = 0;
      for (uint32_t b = 0; b < B; ++b) {
        const CellWindow w = brickWindow({n, 1, 1}, {B, 1, 1}, {b, 0, 0});
        EXPECT_EQ(w.first[0], next);
        EXPECT_LT(w.first[0], w.end[0]);
        next = w.end[0];
      }
      EXPECT_EQ(next, n);
    }
  EXPECT_THROW(checkBrickCounts({4, 4, 4}, {5, 1, 1}), UsageError);
  EXPECT_THROW(checkBrickCounts({4, 4, 4}, {1, 0, 1}), UsageError);
  EXPECT_NO_THROW(checkBrickCounts({4, 4, 4}, {4, 4, 4}));
  EXPECT_EQ(brickIndex({3, 4, 5}, brickNumber({3, 4, 5}, {2, 1, 3})), (std::array<uint32_t, 3>{2, 1, 3}));
}

// Solid runs split by brick: every piece inside its brick, and merging the pieces again gives back the runs exactly,
// including runs that cross row ends and z layers.
TEST(BrickLayout, SolidRunsSplitByBrickMergeBackExactly) {
  const std::array<uint32_t, 3> dims{7, 5, 4};
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<CellRun> runs;
    for (uint64_t key = rng() % 9; key < uint64_t(dims[0]) * dims[1] * dims[2];) {
      const uint64_t count = std::min<uint64_t>(1 + rng() % (trial % 2 ? 40 : 6), 140 - key);
      runs.push_back({key, count});
      key += count + 1 + rng() % 12;
    }
    for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {7, 5, 4}, {3, 2, 3}, {1, 5, 2}, {1, 1, 4}}) {
      std::vector<CellRun> merged;
      uint64_t last = 0;
      for (const auto& [number, pieces] : splitRunsByBrick(runs, dims, bricks)) {
        EXPECT_TRUE(merged.empty() || number > last);
        last = number;
        const CellWindow w = brickWindow(dims, bricks, brickIndex(bricks, number));
        for (size_t p = 0; p < pieces.size(); ++p) {
          EXPECT_TRUE(p == 0 || pieces[p - 1].first + pieces[p - 1].count < pieces[p].first);
          for (uint64_t key = pieces[p].first; key < pieces[p].first + pieces[p].count; ++key) {
            const auto ijk = cellIndex(dims, key);
            for (int a = 0; a < 3; ++a) EXPECT_TRUE(ijk[a] >= w.first[a] && ijk[a] < w.end[a]) << key;
          }
        }
        merged.insert(merged.end(), pieces.begin(), pieces.end());
      }
      std::sort(merged.begin(), merged.end(), [](const CellRun& a, const CellRun& b) { return a.first < b.first; });
      std::vector<CellRun> back;
      for (const CellRun& r : merged) appendSolidRun(back, r);
      ASSERT_EQ(back.size(), runs.size());
      for (size_t r = 0; r < runs.size(); ++r) {
        EXPECT_EQ(back[r].first, runs[r].first);
        EXPECT_EQ(back[r].count, runs[r].count);
      }
    }
  }
}

}  // namespace
}  // namespace vox
