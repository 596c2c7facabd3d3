// Solid fill: enclosed empty cells become solid, open surfaces enclose nothing.
#include <gtest/gtest.h>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

// A closed axis-aligned box surface [a, b]^3 of 12 triangles.
Scene boxScene(double a, double b) {
  Scene scene;
  scene.materials.push_back({});
  Vec3 p[8];
  for (int c = 0; c < 8; ++c) p[c] = {(c & 1) ? b : a, (c & 2) ? b : a, (c & 4) ? b : a};
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& q : quads) {
    scene.triangles.push_back({{p[q[0]], p[q[1]], p[q[2]]}});
    scene.triangles.push_back({{p[q[0]], p[q[2]], p[q[3]]}});
  }
  return scene;
}

TEST(Fill, ClosedBoxInteriorIsSolid) {
  // Box faces at 0.1 and 0.9 inside [0, 1] with 10 cells: faces lie inside cells 1 and 8 (not on boundaries), so the
  // shell is one cell thick and the interior is cells 2..7 on each axis.
  Scene scene = boxScene(0.15, 0.85);
  VoxelizeOptions opt;
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  opt.dims = {10, 10, 10};
  Grid grid = voxelizeScene(scene, opt);
  fillSolid(grid, 1 << 20);
  EXPECT_EQ(grid.solidCount(), 6u * 6 * 6);
  std::vector<uint64_t> solidKeys;
  for (const CellRun& r : grid.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) solidKeys.push_back(key);
  for (uint64_t key : solidKeys) {
    const auto ijk = cellIndex(grid.dims, key);
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(ijk[a], 2u);
      EXPECT_LE(ijk[a], 7u);
    }
  }
}

TEST(Fill, OpenSurfaceEnclosesNothingAndSphereIsFilled) {
  Scene scene = boxScene(0.15, 0.85);
  scene.triangles.pop_back();
  scene.triangles.pop_back();  // one face removed: the box is open
  VoxelizeOptions opt;
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  opt.dims = {10, 10, 10};
  Grid open = voxelizeScene(scene, opt);
  fillSolid(open, 1 << 20);
  EXPECT_TRUE(open.solidRuns.empty());

  Scene ball;
  ball.materials.push_back({});
  ball.spheres.push_back({{0, 0, 0}, 1, {}, 0});
  VoxelizeOptions so;
  so.dims = {15, 15, 15};
  Grid g = voxelizeScene(ball, so);
  fillSolid(g, 1 << 20);
  // Every solid cell is strictly inside the ball and every empty cell strictly inside it is solid.
  size_t inside = 0;
  for (uint32_t k = 0; k < 15; ++k)
    for (uint32_t j = 0; j < 15; ++j)
      for (uint32_t i = 0; i < 15; ++i) {
        const Box b = cellBox(g, i, j, k);
        const uint64_t key = cellKey(g.dims, i, j, k);
        const bool occupied = findCell(g, key) >= 0;
        double far = 0;
        for (int a = 0; a < 3; ++a) far += std::max(b.lo[a] * b.lo[a], b.hi[a] * b.hi[a]);
        const bool solid = isSolid(g, key);
        if (!occupied && far < 1) ++inside;
        EXPECT_EQ(solid, !occupied && far < 1) << i << " " << j << " " << k;
      }
  EXPECT_GT(inside, 100u);
  EXPECT_THROW(fillSolid(g, 10), LimitError);
}

}  // namespace
}  // namespace vox
