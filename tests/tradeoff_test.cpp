// The speed-accuracy benchmark (bench/tradeoff_core.h) in its small mode, so it cannot rot. Its numbers are not
// asserted; its invariants are: bbox never misses, exact equals the rational reference, and grids of the exact,
// sat and bbox methods trace the same image as brute force.
#include <gtest/gtest.h>

#include "reference_overlap.h"
#include "tradeoff_core.h"

namespace vox {
namespace {

TEST(Tradeoff, SmallModeInvariants) {
  bench::TradeoffOptions options;
  options.resolutions = {4, 9};
  options.imageSize = 24;
  size_t rows = 0;
  for (const auto& ts : bench::tradeoffScenes(VOX_SEED_DIR, true)) {
    SCOPED_TRACE(ts.name);
    for (const auto& row : bench::measureTradeoff(ts, options)) {
      ++rows;
      SCOPED_TRACE(row.method + " res " + std::to_string(row.resolution));
      if (row.method == "bbox") {
        EXPECT_EQ(row.refsMissed, 0u);
        EXPECT_EQ(row.cellsMissed, 0u);
      }
      if (row.method == "exact") {
        EXPECT_EQ(row.refsAdded + row.refsMissed, 0u);
      }
      if (row.method != "center") {
        EXPECT_EQ(row.pixelsDiffering, 0u);
      }
      EXPECT_GT(row.references, 0u);
      EXPECT_EQ(row.pixels, 24u * 24u);
      EXPECT_FALSE(bench::csvLine(row).empty());
    }
    // The exact grid of this scene at the smallest resolution, cell by cell, against the rational reference.
    VoxelizeOptions vo;
    vo.resolution = 4;
    const Grid g = voxelizeScene(ts.scene, vo);
    for (uint32_t k = 0; k < g.dims[2]; ++k)
      for (uint32_t j = 0; j < g.dims[1]; ++j)
        for (uint32_t i = 0; i < g.dims[0]; ++i) {
          const int64_t c = findCell(g, cellKey(g.dims, i, j, k));
          const Box box = cellBox(g, i, j, k);
          for (uint32_t t = 0; t < ts.scene.triangles.size(); ++t) {
            bool held = false;
            if (c >= 0)
              for (uint32_t p : g.cellPrims(size_t(c))) held |= p == t;
            ASSERT_EQ(held, reference::triangleMeetsBox(ts.scene.triangles[t], box))
                << i << " " << j << " " << k << " t " << t;
          }
        }
  }
  EXPECT_GT(rows, 20u);
}

}  // namespace
}  // namespace vox
