// Bricks of a grid set (voxelize/bricks.h, voxelizeBrick): every brick holds exactly the single grid's cells inside
// it, primitive for primitive, for every brick count, method and kind of primitive.
#include "vox/voxelize/bricks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "test_util.h"
#include "vox/core/error.h"

namespace vox {
namespace {

// The single grid's cells restricted to a window, as (key, prims) pairs.
using Cells = std::vector<std::pair<uint64_t, std::vector<uint32_t>>>;
Cells cellsOf(const Grid& g, const CellWindow* w) {
  Cells out;
  for (size_t c = 0; c < g.occupiedCount(); ++c) {
    const auto ijk = cellIndex(g.dims, g.cellKeys[c]);
    bool in = true;
    for (int a = 0; a < 3 && w; ++a) in = in && ijk[a] >= w->first[a] && ijk[a] < w->end[a];
    if (in) out.emplace_back(g.cellKeys[c], std::vector<uint32_t>(g.cellPrims(c).begin(), g.cellPrims(c).end()));
  }
  return out;
}

// Voxelizes every brick and checks it against the single grid; returns the number of cells the bricks hold.
size_t expectBricksEqualSingle(const Scene& scene, const VoxelizeOptions& options,
                               const std::array<uint32_t, 3>& bricks) {
  const Grid single = voxelizeScene(scene, options);
  Grid plan = planGrid(scene, options);
  if (options.bounds) plan.outsidePrims = primitivesOutside(scene, plan);
  EXPECT_EQ(plan.outsidePrims, single.outsidePrims);
  const auto candidates = brickCandidates(scene, plan, bricks, uint64_t(1) << 30);
  EXPECT_EQ(candidates.size(), size_t(bricks[0]) * bricks[1] * bricks[2]);
  size_t total = 0;
  for (uint64_t b = 0; b < candidates.size(); ++b) {
    const CellWindow w = brickWindow(plan.dims, bricks, brickIndex(bricks, b));
    const Grid brick = voxelizeBrick(scene, plan, w, candidates[b], options);
    const Cells got = cellsOf(brick, nullptr), want = cellsOf(single, &w);
    EXPECT_EQ(got, want) << "brick " << b << " of " << bricks[0] << "x" << bricks[1] << "x" << bricks[2];
    total += got.size();
  }
  EXPECT_EQ(total, single.occupiedCount());
  return total;
}

Triangle tri(Vec3 a, Vec3 b, Vec3 c) {
  Triangle t;
  t.v = {a, b, c};
  return t;
}

// Triangles spanning many bricks, small ones, degenerate ones, spheres and ellipsoids, and planes (never in cells).
Scene mixedScene(uint32_t seed) {
  Scene s = testing::randomScene(seed, 40, 4, -1, 2);
  s.triangles.push_back(tri({-1, -1, -1}, {1, 1, 1}, {1, -1, 0.3}));  // across the whole grid
  s.planes.push_back({{0, 0, 1}, 0.25, 0});
  return s;
}

TEST(Bricks, EveryBrickCountUpTo7x5x3EqualsTheSingleGrid) {
  const Scene scene = mixedScene(1);
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{14, 11, 9};
  for (uint32_t bz = 1; bz <= 3; ++bz)
    for (uint32_t by = 1; by <= 5; ++by)
      for (uint32_t bx = 1; bx <= 7; ++bx) EXPECT_GT(expectBricksEqualSingle(scene, o, {bx, by, bz}), 0u);
}

TEST(Bricks, BricksOfOneCellAndEveryMethod) {
  const Scene scene = mixedScene(2);
  for (const auto method : {OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox, OverlapMethod::Center}) {
    VoxelizeOptions o;
    o.method = method;
    o.dims = std::array<uint32_t, 3>{9, 7, 5};
    expectBricksEqualSingle(scene, o, {9, 7, 5});
    expectBricksEqualSingle(scene, o, {4, 3, 2});
  }
}

TEST(Bricks, UserBoundsWithPrimitivesOutside) {
  const Scene scene = mixedScene(3);
  VoxelizeOptions o;
  o.bounds = Box{{-0.5, -0.6, -0.4}, {0.7, 0.5, 0.6}};
  o.dims = std::array<uint32_t, 3>{12, 10, 8};
  const Grid single = voxelizeScene(scene, o);
  ASSERT_FALSE(single.outsidePrims.empty());
  expectBricksEqualSingle(scene, o, {5, 3, 2});
}

TEST(Bricks, LatticeAlignedContactsAtBrickFaces) {
  // Triangles lying in cell faces that are brick faces: both neighbouring bricks must take them, as the single grid
  // does (a contact belongs to every closed cell it touches).
  Scene s;
  s.materials.push_back({});
  s.triangles.push_back(tri({0.5, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}));
  s.triangles.push_back(tri({0, 0.25, 0}, {1, 0.25, 1}, {0, 0.25, 1}));
  s.triangles.push_back(tri({0.25, 0.75, 0.5}, {0.25, 0.75, 0.5}, {0.25, 0.75, 0.5}));  // a point on a corner
  Sphere ball;
  ball.center = {0.5, 0.5, 0.5};
  ball.radius = 0.25;
  s.spheres.push_back(ball);
  VoxelizeOptions o;
  o.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  o.dims = std::array<uint32_t, 3>{8, 8, 8};
  for (uint32_t b : {1u, 2u, 4u, 8u, 3u}) expectBricksEqualSingle(s, o, {b, b, b});
}

TEST(Bricks, LayoutCoversEveryCellOnce) {
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

TEST(Bricks, CandidateListsAreRefusedBeforeTheyOutgrowMemory) {
  Scene s;
  s.materials.push_back({});
  s.triangles.push_back(tri({0, 0, 0}, {1, 1, 1}, {1, 0, 0}));
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{64, 64, 64};
  const Grid plan = planGrid(s, o);
  EXPECT_THROW(brickCandidates(s, plan, {64, 64, 64}, 1 << 20), LimitError);
}

// Solid runs split by brick: every piece inside its brick, and merging the pieces again gives back the runs exactly,
// including runs that cross row ends and z layers.
TEST(Bricks, SolidRunsSplitByBrickMergeBackExactly) {
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
