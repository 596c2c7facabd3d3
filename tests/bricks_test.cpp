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

TEST(Bricks, CandidateListsAreRefusedBeforeTheyOutgrowMemory) {
  Scene s;
  s.materials.push_back({});
  s.triangles.push_back(tri({0, 0, 0}, {1, 1, 1}, {1, 0, 0}));
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{64, 64, 64};
  const Grid plan = planGrid(s, o);
  EXPECT_THROW(brickCandidates(s, plan, {64, 64, 64}, 1 << 20), LimitError);
}

}  // namespace
}  // namespace vox
