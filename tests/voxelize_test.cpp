// Voxelization at the grid level: the exact grid equals the rational reference cell by cell; bbox contains exact;
// center and sat differences are counted; seed scenes voxelize with their command-line grid sizes; bad options.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "reference_overlap.h"
#include "seed_cases.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/voxelize/overlap.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using CellSet = std::set<std::pair<uint64_t, uint32_t>>;

CellSet references(const Grid& g) {
  CellSet out;
  for (size_t c = 0; c < g.occupiedCount(); ++c)
    for (uint32_t p : g.cellPrims(c)) out.insert({g.cellKeys[c], p});
  return out;
}

// Reference membership of primitive `id` in cell (i,j,k), independent of libvox's overlap code for triangles and
// plain spheres; ellipsoids use the library's exact test (checked separately in overlap_test).
bool referenceMeets(const Scene& s, uint32_t id, const Box& cell) {
  if (id < s.triangles.size()) return reference::triangleMeetsBox(s.triangles[id], cell);
  const Sphere& sp = s.spheres[id - s.triangles.size()];
  if (sp.isEllipsoid()) return sphereBoxExact(sp, cell);
  return reference::sphereSurfaceMeetsBox(sp.center, sp.radius, cell);
}

void expectExactGrid(const Scene& scene, const Grid& grid) {
  const CellSet got = references(grid);
  size_t expectedCount = 0;
  for (uint32_t k = 0; k < grid.dims[2]; ++k)
    for (uint32_t j = 0; j < grid.dims[1]; ++j)
      for (uint32_t i = 0; i < grid.dims[0]; ++i) {
        const Box cell = cellBox(grid, i, j, k);
        const uint64_t key = cellKey(grid.dims, i, j, k);
        for (uint32_t id = 0; id < scene.boundedCount(); ++id) {
          const bool expected = referenceMeets(scene, id, cell);
          expectedCount += expected;
          ASSERT_EQ(got.count({key, id}) == 1, expected) << "cell " << i << " " << j << " " << k << " prim " << id;
        }
      }
  EXPECT_EQ(expectedCount, got.size());
}

// Checks every cell of each triangle's bounding range widened by one cell against the reference; returns how many.
size_t expectExactAroundTriangles(const Scene& scene, const Grid& grid) {
  const CellSet got = references(grid);
  size_t checked = 0;
  for (uint32_t id = 0; id < scene.triangles.size(); ++id) {
    const Box tb = triangleBounds(scene.triangles[id]);
    std::array<int64_t, 2> r[3];
    for (int a = 0; a < 3; ++a) {
      r[a] = cellRange(grid.bounds, grid.dims, a, tb.lo[a], tb.hi[a]);
      r[a][0] = std::max<int64_t>(0, r[a][0] - 1);
      r[a][1] = std::min<int64_t>(grid.dims[a] - 1, r[a][1] + 1);
    }
    for (int64_t k = r[2][0]; k <= r[2][1]; ++k)
      for (int64_t j = r[1][0]; j <= r[1][1]; ++j)
        for (int64_t i = r[0][0]; i <= r[0][1]; ++i) {
          const bool expected = reference::triangleMeetsBox(scene.triangles[id], cellBox(grid, i, j, k));
          EXPECT_EQ(got.count({cellKey(grid.dims, i, j, k), id}) == 1, expected)
              << "prim " << id << " cell " << i << " " << j << " " << k;
          ++checked;
        }
  }
  return checked;
}

TEST(Voxelize, ExactEqualsReferenceOnRandomScenes) {
  const std::array<uint32_t, 3> dimsList[] = {{1, 1, 1}, {2, 3, 1}, {7, 7, 7}, {16, 5, 9}, {12, 12, 12}};
  for (uint32_t seed = 0; seed < 5; ++seed) {
    const Scene scene = testing::randomScene(seed, 25, 4, seed == 3 ? 1e7 : 0.0, seed == 4 ? 1e-6 : 1.0);
    VoxelizeOptions opt;
    opt.dims = dimsList[seed];
    const Grid grid = voxelizeScene(scene, opt);
    SCOPED_TRACE("seed " + std::to_string(seed));
    expectExactGrid(scene, grid);
  }
}

TEST(Voxelize, ExactOnLatticeAlignedTriangles) {
  // Vertices on cell corners, triangles in cell planes and along cell edges: every contact is exactly on a boundary.
  Scene scene;
  scene.materials.push_back({});
  const double h = 0.25;  // 4 cells over [0, 1]
  auto p = [&](int i, int j, int k) { return Vec3{i * h, j * h, k * h}; };
  scene.triangles.push_back({{p(0, 0, 0), p(4, 0, 0), p(0, 4, 0)}});  // in the plane z = 0
  scene.triangles.push_back({{p(1, 1, 2), p(3, 1, 2), p(1, 3, 2)}});  // in the plane z = 0.5
  scene.triangles.push_back({{p(2, 0, 4), p(2, 4, 4), p(2, 2, 4)}});  // collinear, along x = 0.5, z = 1
  scene.triangles.push_back({{p(1, 1, 1), p(1, 1, 1), p(1, 1, 1)}});  // a point on a lattice corner (8 cells)
  scene.triangles.push_back({{p(0, 0, 0), p(4, 4, 4), p(4, 0, 4)}});  // diagonal through cell corners
  VoxelizeOptions opt;
  opt.dims = {4, 4, 4};
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  const Grid grid = voxelizeScene(scene, opt);
  expectExactGrid(scene, grid);
  // The point on a lattice corner belongs to the 8 cells around it.
  size_t pointCells = 0;
  for (const auto& [key, id] : references(grid)) pointCells += id == 3;
  EXPECT_EQ(pointCells, 8u);
}

TEST(Voxelize, LargeGridsMatchReferenceAroundEachTriangle) {
  // At 1024^3 and 2048 x 3 x 1024 the full grid cannot be enumerated; check every cell of each triangle's bounding
  // range widened by one cell (the plane-sweep pruning must not drop any).
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{1024, 1024, 1024}, {2048, 3, 1024}}) {
    Scene scene = testing::randomScene(42, 0, 0);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    for (int n = 0; n < 30; ++n) {
      const Vec3 a{u(rng), u(rng), u(rng)};
      const double e = 0.012;
      scene.triangles.push_back(
          {{a, a + Vec3{e * u(rng), -e * u(rng), e * u(rng)}, a + Vec3{-e * u(rng), e * u(rng), e * u(rng)}}});
    }
    VoxelizeOptions opt;
    opt.dims = dims;
    opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
    const Grid grid = voxelizeScene(scene, opt);
    const size_t checked = expectExactAroundTriangles(scene, grid);
    EXPECT_GT(checked, 10000u);
  }
}

TEST(Voxelize, BboxContainsExactAndMethodsAreCounted) {
  const Scene scene = testing::randomScene(7, 200, 6);
  VoxelizeOptions opt;
  opt.dims = {24, 24, 24};
  auto run = [&](OverlapMethod m) {
    opt.method = m;
    return references(voxelizeScene(scene, opt));
  };
  const CellSet exact = run(OverlapMethod::Exact), bbox = run(OverlapMethod::BBox), sat = run(OverlapMethod::Sat),
                center = run(OverlapMethod::Center);
  for (const auto& ref : exact) ASSERT_TRUE(bbox.count(ref)) << "bbox misses a cell of exact";
  auto diff = [](const CellSet& a, const CellSet& b) {
    size_t n = 0;
    for (const auto& x : a) n += !b.count(x);
    return n;
  };
  EXPECT_GT(bbox.size(), exact.size());
  EXPECT_GT(diff(exact, center), 0u) << "center is expected to miss cells";
  RecordProperty("bbox_added", int(diff(bbox, exact)));
  RecordProperty("center_missed", int(diff(exact, center)));
  RecordProperty("center_added", int(diff(center, exact)));
  RecordProperty("sat_missed", int(diff(exact, sat)));
  RecordProperty("sat_added", int(diff(sat, exact)));
  // On ordinary (non-adversarial) data the floating-point test agrees with the exact one.
  EXPECT_EQ(diff(exact, sat) + diff(sat, exact), 0u);
}

TEST(Voxelize, PlanesOnlySceneGetsEmptyUnitGrid) {
  Scene scene;
  scene.materials.push_back({});
  scene.planes.push_back({{0, 1, 0}, -1, 0});
  const Grid grid = voxelizeScene(scene, {});
  EXPECT_EQ(grid.dims, (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(grid.occupiedCount(), 0u);
}

TEST(Voxelize, FlatSceneIsPaddedAndUserBoundsReportOutsidePrimitives) {
  Scene scene;
  scene.materials.push_back({});
  scene.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}});
  Grid grid = voxelizeScene(scene, {});
  EXPECT_LT(grid.bounds.lo.z, 0.0);
  EXPECT_GT(grid.bounds.hi.z, 0.0);
  EXPECT_GT(grid.occupiedCount(), 0u);
  VoxelizeOptions opt;
  opt.bounds = Box{{0, 0, -1}, {0.5, 0.5, 1}};
  opt.dims = {4, 4, 4};
  grid = voxelizeScene(scene, opt);
  EXPECT_EQ(grid.outsidePrims, std::vector<uint32_t>{0});
  EXPECT_GT(grid.occupiedCount(), 0u);
}

TEST(Voxelize, BadDimensionsAndAbsurdSizes) {
  const Scene scene = testing::randomScene(3, 10, 1);
  VoxelizeOptions opt;
  opt.dims = {0, 4, 4};
  EXPECT_THROW(voxelizeScene(scene, opt), UsageError);
  opt.dims = {kMaxCellsPerAxis + 1, 4, 4};
  EXPECT_THROW(voxelizeScene(scene, opt), UsageError);
  opt.dims.reset();
  opt.resolution = 0;
  EXPECT_THROW(voxelizeScene(scene, opt), UsageError);
  // 100000^3 over a large sphere cannot fit: refused before allocating.
  Scene big;
  big.materials.push_back({});
  big.spheres.push_back({{0, 0, 0}, 1, {}, 0});
  opt.resolution.reset();
  opt.dims = {100000, 100000, 100000};
  opt.memoryLimitBytes = 1ull << 30;
  EXPECT_THROW(voxelizeScene(big, opt), LimitError);
  // 100000^3 over a few small triangles fits and works.
  Scene small;
  small.materials.push_back({});
  small.triangles.push_back({{Vec3{0.5, 0.5, 0.5}, Vec3{0.50002, 0.5, 0.5}, Vec3{0.5, 0.50003, 0.50001}}});
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  const Grid g = voxelizeScene(small, opt);
  EXPECT_GT(g.occupiedCount(), 0u);
  EXPECT_LT(g.occupiedCount(), 100u);
  EXPECT_GT(expectExactAroundTriangles(small, g), 0u);
}

// Assignment 5 and 6 command lines of the seed README, with their grid sizes.
using testing::kSeedCases;

TEST(Voxelize, SeedScenesWithTheirGridSizes) {
  for (const auto& c : kSeedCases) {
    SCOPED_TRACE(c.file);
    const Scene scene = loadScene(std::string(VOX_SEED_DIR) + "/6837/scenes/" + c.file);
    VoxelizeOptions opt;
    opt.dims = c.dims;
    const Grid exact = voxelizeScene(scene, opt);
    opt.method = OverlapMethod::BBox;
    const Grid bbox = voxelizeScene(scene, opt);
    EXPECT_EQ(exact.dims, c.dims);
    // Every bounded primitive is somewhere (default bounds contain them all), and bbox contains exact.
    std::vector<bool> seen(scene.boundedCount(), false);
    for (uint32_t p : exact.primIds) seen[p] = true;
    for (size_t p = 0; p < seen.size(); ++p) ASSERT_TRUE(seen[p]) << "primitive " << p << " in no cell";
    const CellSet e = references(exact), b = references(bbox);
    for (const auto& ref : e) ASSERT_TRUE(b.count(ref));
    if (c.dims == std::array<uint32_t, 3>{1, 1, 1}) {
      EXPECT_EQ(exact.occupiedCount(), 1u);
    }
  }
}

}  // namespace
}  // namespace vox
