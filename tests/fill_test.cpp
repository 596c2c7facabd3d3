// Solid fill: closed surfaces by flood fill (cell for cell against a dense reference), open meshes by the winding
// number (against brute force), spheres and ellipsoids against the exact cells of the closed solid, the open Stanford
// bunny against its closed course twin.
#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <memory>
#include <random>
#include <span>

#include "exact_side.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/voxelize/bricks.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"
#include "vox/voxelize/winding_number.h"

namespace vox {
namespace {

using testing::kSanitized;

using testing::seed;

std::vector<uint8_t> solidMask(const Grid& g) {
  std::vector<uint8_t> mask(g.cellCount(), 0);
  for (const CellRun& r : g.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) mask[key] = 1;
  return mask;
}

// Reference: breadth-first flood fill of single cells from every empty cell on the grid's faces; what it does not
// reach is enclosed.
std::vector<uint8_t> referenceEnclosed(const Grid& g) {
  const auto d = g.dims;
  std::vector<uint8_t> state(g.cellCount(), 0);  // 0 free, 1 occupied, 2 reached
  for (uint64_t key : g.cellKeys) state[key] = 1;
  std::deque<std::array<int64_t, 3>> queue;
  auto visit = [&](int64_t i, int64_t j, int64_t k) {
    if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2]) return;
    uint8_t& s = state[cellKey(d, i, j, k)];
    if (s == 0) s = 2, queue.push_back({i, j, k});
  };
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i)
        if (i == 0 || j == 0 || k == 0 || i == d[0] - 1 || j == d[1] - 1 || k == d[2] - 1) visit(i, j, k);
  while (!queue.empty()) {
    const auto [i, j, k] = queue.front();
    queue.pop_front();
    visit(i - 1, j, k), visit(i + 1, j, k), visit(i, j - 1, k), visit(i, j + 1, k), visit(i, j, k - 1),
        visit(i, j, k + 1);
  }
  std::vector<uint8_t> enclosed(g.cellCount());
  for (uint64_t c = 0; c < enclosed.size(); ++c) enclosed[c] = state[c] == 0;
  return enclosed;
}

void expectRunsWellFormed(const Grid& g) {
  EXPECT_NO_THROW(checkSolidRuns(g.solidRuns, g.cellCount(), "fill"));
  for (const CellRun& r : g.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) ASSERT_LT(findCell(g, key), 0) << key;
}

TEST(Fill, ClosedBoxInteriorIsSolid) {
  // Faces at 0.15 and 0.85 in [0, 1] with 10 cells: inside cells 1 and 8, so the interior is cells 2..7 per axis.
  Scene scene = testing::boxScene(0.15, 0.85);
  VoxelizeOptions opt;
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  opt.dims = {10, 10, 10};
  Grid grid = voxelizeScene(scene, opt);
  const FillReport report = fillSolid(grid, scene);
  EXPECT_EQ(report.rule, FillRule::Enclosed);
  EXPECT_EQ(report.openEdges, 0u);
  EXPECT_EQ(grid.solidCount(), 6u * 6 * 6);
  EXPECT_EQ(report.solidCells, grid.solidCount());
  EXPECT_EQ(grid.solidRuns.size(), 6u * 6);  // one run per row
  for (const CellRun& r : grid.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) {
      const auto ijk = cellIndex(grid.dims, key);
      for (int a = 0; a < 3; ++a) EXPECT_TRUE(ijk[a] >= 2 && ijk[a] <= 7) << key;
    }
  EXPECT_EQ(describeFill(report), "closed surface, 216 solid cells");
  EXPECT_EQ(fillWarning(report), "");
}

// The run-based flood fill against the dense reference on random soups of triangles, spheres and ellipsoids,
// including grids one cell thick, where every cell is on the grid's boundary.
TEST(Fill, EnclosedRunsEqualDenseFloodFill) {
  const std::array<uint32_t, 3> dims[] = {{23, 17, 19}, {40, 1, 30}, {1, 25, 25}, {31, 29, 2}, {7, 64, 9}};
  int checked = 0;
  for (uint32_t s = 0; s < 12; ++s) {
    Scene scene = testing::randomScene(900 + s, 40 + 10 * int(s), 6);
    scene.triangles.clear();  // closed surfaces only, so that the rule is the flood fill
    const Scene box = testing::boxScene(0.05 + 0.01 * s, 0.9);
    scene.triangles = box.triangles;
    VoxelizeOptions opt;
    opt.dims = dims[s % std::size(dims)];
    Grid g = voxelizeScene(scene, opt);
    const FillReport report = fillSolid(g, scene);
    ASSERT_EQ(report.rule, FillRule::Enclosed);
    expectRunsWellFormed(g);
    const auto want = referenceEnclosed(g), got = solidMask(g);
    uint64_t wantCount = 0;
    for (uint64_t c = 0; c < want.size(); ++c) {
      ASSERT_EQ(got[c], want[c]) << "scene " << s << " cell " << c;
      wantCount += want[c];
    }
    EXPECT_EQ(report.solidCells, wantCount);
    checked += wantCount > 0;
  }
  EXPECT_GE(checked, 4);  // the comparison saw interiors (grids one cell thick have none)
}

// DESIGN.md: a solid cell lies inside and meets no surface, so occupied or solid is exactly "meets the closed solid".
// For an axis-aligned ellipsoid (x/a)^2 + (y/b)^2 + (z/c)^2 <= 1 the nearest and farthest points of a box are found
// axis by axis.
void expectExactSolid(const Sphere& s, const Vec3& semi, const std::array<uint32_t, 3>& dims) {
  Scene scene;
  scene.materials.push_back({});
  scene.spheres.push_back(s);
  VoxelizeOptions opt;
  opt.dims = dims;
  Grid g = voxelizeScene(scene, opt);
  const FillReport report = fillSolid(g, scene);
  EXPECT_EQ(report.rule, FillRule::Enclosed);
  expectRunsWellFormed(g);
  const auto solid = solidMask(g);
  uint64_t inside = 0;
  for (uint32_t k = 0; k < dims[2]; ++k)
    for (uint32_t j = 0; j < dims[1]; ++j)
      for (uint32_t i = 0; i < dims[0]; ++i) {
        const Box b = cellBox(g, i, j, k);
        double nearQ = 0, farQ = 0;
        for (int a = 0; a < 3; ++a) {
          const double lo = (b.lo[a] - s.center[a]) / semi[a], hi = (b.hi[a] - s.center[a]) / semi[a];
          const double nearest = lo > 0 ? lo : (hi < 0 ? hi : 0);
          nearQ += nearest * nearest;
          farQ += std::max(lo * lo, hi * hi);
        }
        const uint64_t key = cellKey(g.dims, i, j, k);
        const bool occupied = findCell(g, key) >= 0;
        ASSERT_EQ(occupied || solid[key], nearQ <= 1) << i << " " << j << " " << k;
        inside += solid[key];
        if (!occupied) {
          ASSERT_EQ(solid[key], farQ < 1) << i << " " << j << " " << k;
        }
      }
  EXPECT_GT(inside, uint64_t(dims[0]) * dims[1] * dims[2] / 8);
}

TEST(Fill, SphereAndEllipsoidEqualTheClosedSolid) {
  const uint32_t n = kSanitized ? 21 : 47;
  expectExactSolid({{0.1, -0.2, 0.3}, 1, {}, 0}, {1, 1, 1}, {n, n, n});
  expectExactSolid({{0, 0, 0}, 0.75, {}, 0}, {0.75, 0.75, 0.75}, {n, n + 4, n - 6});
  Sphere e{{0, 0, 0}, 1, scaling({1.5, 0.6, 1.1}), 0};
  expectExactSolid(e, {1.5, 0.6, 1.1}, {n + 2, n, n - 3});
}

// Flood fill and the winding number agree on a closed mesh (the winding number is 1 inside it, 0 outside).
TEST(Fill, CourseBunnyWindingNumberEqualsFloodFill) {
  const Scene bunny = loadScene(seed(kSanitized ? "6837/scenes/bunny_1k.obj" : "6837/scenes/bunny_40k.obj"));
  VoxelizeOptions opt;
  opt.resolution = kSanitized ? 24 : 64;
  Grid flood = voxelizeScene(bunny, opt);
  const FillReport closed = fillSolid(flood, bunny);
  ASSERT_EQ(closed.rule, FillRule::Enclosed) << closed.openEdges;
  EXPECT_GT(closed.solidCells, 1000u);
  const auto want = referenceEnclosed(flood), got = solidMask(flood);
  EXPECT_EQ(got, want);
  // The same gaps decided by winding number alone: every enclosed run has |w| >= 0.5, every other < 0.5.
  Grid winding = flood;
  FillOptions fo;
  fo.rule = FillRule::WindingNumber;
  fo.windingOnly = true;
  const FillReport w = fillSolid(winding, bunny, fo);
  EXPECT_EQ(w.enclosedCells, 0u);
  EXPECT_GT(w.windingQueries, 0u);
  EXPECT_EQ(solidMask(winding), want);
}

TEST(Fill, OpenBoxIsReportedOpenAndFilledByWindingNumber) {
  Scene scene = testing::boxScene(0.15, 0.85);
  scene.triangles.resize(10);  // the last face (x = 0.85) removed: a large hole
  VoxelizeOptions opt;
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  opt.dims = {20, 20, 20};
  Grid g = voxelizeScene(scene, opt);
  const FillReport report = fillSolid(g, scene);
  EXPECT_EQ(report.rule, FillRule::WindingNumber);
  EXPECT_EQ(report.openEdges, 4u);  // the square rim of the hole
  EXPECT_EQ(report.enclosedCells, 0u);
  EXPECT_GT(report.windingQueries, 0u);
  expectRunsWellFormed(g);
  // Brute force: every empty cell between two occupied cells of its row is solid when the exact winding number at
  // its run's middle cell is at least 0.5; and per cell, the exact winding number at each cell's own centre agrees
  // with the run's decision almost everywhere (the runs end at the surface, except near the hole).
  const auto solid = solidMask(g);
  uint64_t cells = 0, disagree = 0;
  for (uint32_t k = 0; k < 20; ++k)
    for (uint32_t j = 0; j < 20; ++j)
      for (uint32_t i = 0; i < 20; ++i) {
        const uint64_t key = cellKey(g.dims, i, j, k);
        if (findCell(g, key) >= 0) continue;
        const Box b = cellBox(g, i, j, k);
        const double w = windingNumberExact(scene.triangles, (b.lo + b.hi) * 0.5);
        ++cells;
        disagree += solid[key] != (std::abs(w) >= 0.5);
      }
  EXPECT_GT(report.solidCells, 5u * 5 * 5);
  EXPECT_LT(double(disagree), 0.02 * double(cells)) << disagree << " of " << cells;
  EXPECT_NE(describeFill(report).find("mesh has 4 open edges"), std::string::npos) << describeFill(report);
}

// The scanned bunny (holes in its base) fills like the course's closed bunny of the same shape (twice its size).
TEST(Fill, OpenStanfordBunnyFillsLikeItsClosedTwin) {
  const uint32_t res = kSanitized ? 48 : 128;
  const Scene open = loadScene(seed("meshes/bun_zipper.ply"));
  const Scene closed = loadScene(seed("6837/scenes/bunny_40k.obj"));
  VoxelizeOptions opt;
  opt.resolution = res;
  Grid go = voxelizeScene(open, opt), gc = voxelizeScene(closed, opt);
  const FillReport ro = fillSolid(go, open), rc = fillSolid(gc, closed);
  EXPECT_EQ(rc.rule, FillRule::Enclosed);
  EXPECT_EQ(ro.rule, FillRule::WindingNumber);
  EXPECT_GT(ro.openEdges, 0u);
  EXPECT_GT(rc.solidCells, 1000u);
  const double ratio = double(ro.solidCells + go.occupiedCount()) / double(rc.solidCells + gc.occupiedCount());
  EXPECT_NEAR(ratio, 1.0, 0.03) << ro.solidCells << " + " << go.occupiedCount() << " vs " << rc.solidCells << " + "
                                << gc.occupiedCount();
  EXPECT_EQ(fillWarning(ro), "");
}

// Per cell, the winding number at its centre (accurate tree, beta 8) against the fill's decision, over every empty
// run of the rows that hold a surface cell (the others are outside by definition). The fill decides most cells
// through the holes' caps (an integer per region minus the caps' own winding number), so this checks that route
// against the plain one. A run is decided at its ends and split once (fill.h), so runs whose reference decision
// changes more than once are only counted (`twice`). Returns the cells that disagree although their |w| is farther
// than `margin` from 0.5.
uint64_t capsVersusPlainWinding(const Grid& g, const Scene& scene, double margin, uint64_t* checked = nullptr,
                                uint64_t* twice = nullptr) {
  const WindingTree tree = buildWindingTree(scene.triangles);
  const auto solid = solidMask(g);
  std::vector<uint8_t> rowListed(uint64_t(g.dims[1]) * g.dims[2], 0);
  for (uint64_t key : g.cellKeys) rowListed[key / g.dims[0]] = 1;
  uint64_t wrong = 0, cells = 0, runs = 0, skipped = 0;
  for (uint32_t k = 0; k < g.dims[2]; ++k)
    for (uint32_t j = 0; j < g.dims[1]; ++j) {
      if (!rowListed[j + uint64_t(g.dims[1]) * k]) continue;
      for (uint32_t i = 0; i < g.dims[0];) {
        if (findCell(g, cellKey(g.dims, i, j, k)) >= 0) {
          ++i;
          continue;
        }
        std::vector<std::pair<uint32_t, double>> run;  // cell, |w|
        for (; i < g.dims[0] && findCell(g, cellKey(g.dims, i, j, k)) < 0; ++i) {
          const Box b = cellBox(g, i, j, k);
          run.push_back({i, std::abs(windingNumber(tree, (b.lo + b.hi) * 0.5, 8))});
        }
        int changes = 0;
        for (size_t c = 1; c < run.size(); ++c) changes += (run[c].second >= 0.5) != (run[c - 1].second >= 0.5);
        ++runs;
        if (changes > 1) {
          ++skipped;
          continue;
        }
        for (const auto& [x, w] : run) {
          ++cells;
          if (solid[cellKey(g.dims, x, j, k)] != (w >= kWindingThreshold) && std::abs(w - kWindingThreshold) > margin)
            ++wrong, ADD_FAILURE() << "cell " << x << " " << j << " " << k << ": |w| " << w;
          if (wrong > 5) return wrong;
        }
      }
    }
  if (checked) *checked = cells;
  if (twice) *twice = skipped;
  // Runs that pass under a hole, the threshold dipping in between: a few percent near the holes of these meshes.
  EXPECT_LT(double(skipped), 0.06 * double(runs) + 1) << skipped << " of " << runs << " runs cross 0.5 twice";
  return wrong;
}

TEST(Fill, HoleCapsDecideAsThePlainWindingNumber) {
  VoxelizeOptions opt;
  opt.resolution = kSanitized ? 24 : 48;
  const Scene bunny = loadScene(seed("meshes/bun_zipper.ply"));
  Grid g = voxelizeScene(bunny, opt);
  const FillReport report = fillSolid(g, bunny);
  EXPECT_GT(report.capQueries, 0u);
  uint64_t cells = 0, twice = 0;
  EXPECT_EQ(capsVersusPlainWinding(g, bunny, 0.01, &cells, &twice), 0u);
  EXPECT_GT(cells, 1000u);
  // Boxes with one or two faces missing, at random bounds and orientations: holes that runs cross and pass by.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.05, 0.4);
  for (int round = 0; round < (kSanitized ? 3 : 10); ++round) {
    Scene box = testing::boxScene(u(rng), 1 - u(rng));
    const int face = int(rng() % 6);
    box.triangles.erase(box.triangles.begin() + 2 * face, box.triangles.begin() + 2 * face + 2);
    if (round % 2) box.triangles.erase(box.triangles.begin(), box.triangles.begin() + 1);  // a triangle's hole too
    if (round % 3 == 0)
      for (Triangle& t : box.triangles) std::swap(t.v[1], t.v[2]);  // inward, as scanners often write
    const Mat4 spin = rotation(Vec3{u(rng), u(rng), u(rng)}, 10 * u(rng));
    for (Triangle& t : box.triangles)
      for (Vec3& v : t.v) v = transformPoint(spin, v - Vec3{0.5, 0.5, 0.5});
    VoxelizeOptions bo;
    bo.dims = {uint32_t(17 + round), 23, uint32_t(19 + 2 * round)};
    Grid bg = voxelizeScene(box, bo);
    const FillReport br = fillSolid(bg, box);
    EXPECT_EQ(br.rule, FillRule::WindingNumber);
    EXPECT_EQ(capsVersusPlainWinding(bg, box, 0.01), 0u) << "round " << round;
  }
}

TEST(Fill, SuspiciousResultsAreNamedAndBudgetIsChecked) {
  // User bounds wholly inside a closed box: no cell meets the surface and every cell is inside.
  Scene scene = testing::boxScene(0, 1);
  VoxelizeOptions opt;
  opt.bounds = Box{{0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}};
  opt.dims = {4, 4, 4};
  Grid inside = voxelizeScene(scene, opt);
  FillReport r = fillSolid(inside, scene);
  EXPECT_EQ(r.solidCells, 64u);  // the surfaces outside the bounds count (issue 45)
  EXPECT_EQ(fillWarning(r), "");
  // Bounds beside the box: nothing inside.
  opt.bounds = Box{{1.5, 0.4, 0.4}, {2, 0.6, 0.6}};
  Grid beside = voxelizeScene(scene, opt);
  r = fillSolid(beside, scene);
  EXPECT_EQ(r.solidCells, 0u);
  EXPECT_NE(fillWarning(r).find("nothing filled"), std::string::npos);
  // A closed surface on the grid's faces: nothing is outside.
  opt.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  Grid whole = voxelizeScene(scene, opt);
  r = fillSolid(whole, scene);
  EXPECT_EQ(r.solidCells, 8u);
  EXPECT_EQ(fillWarning(r), "");  // exact under the flood fill
  FillOptions winding;
  winding.rule = FillRule::WindingNumber;
  winding.windingOnly = true;
  r = fillSolid(whole, scene, winding);
  EXPECT_EQ(r.windingCells, 8u);
  EXPECT_EQ(fillWarning(r), "");  // a closed surface filled by winding number on request (--fraction): as exact
  r.openEdges = 4;                // the same full grid from an open mesh: more likely an inside-out surface
  EXPECT_NE(fillWarning(r).find("every empty cell"), std::string::npos);

  FillOptions tiny;
  tiny.memoryLimitBytes = 64;
  EXPECT_THROW(fillSolid(whole, scene, tiny), LimitError);
  FillOptions cancel;
  cancel.rule = FillRule::WindingNumber;
  cancel.progress = [](double) { return false; };
  EXPECT_THROW(fillSolid(whole, scene, cancel), Error);
}

// SlabFill over `grid` in slabs of 1 to maxPlanes planes (random thickness): its runs, concatenated, and its
// counts must be fillSolid's.
void expectSlabFillEqualsFillSolid(const Grid& grid, const Scene& scene, std::mt19937& rng, uint32_t maxPlanes,
                                   const FillOptions& options, const std::string& what) {
  Grid whole = grid;
  const FillReport want = fillSolid(whole, scene, options);
  std::vector<std::pair<uint32_t, uint32_t>> slabs;
  for (uint32_t k0 = 0; k0 < grid.dims[2];) {
    const uint32_t k1 = std::min(grid.dims[2], k0 + 1 + uint32_t(rng() % maxPlanes));
    slabs.push_back({k0, k1});
    k0 = k1;
  }
  const uint64_t plane = uint64_t(grid.dims[0]) * grid.dims[1];
  auto keysOf = [&](uint32_t k0, uint32_t k1) {
    const auto& keys = grid.cellKeys;
    const auto from = std::lower_bound(keys.begin(), keys.end(), k0 * plane);
    return std::span<const uint64_t>(from, std::lower_bound(keys.begin(), keys.end(), k1 * plane));
  };
  SlabFill fill(grid, scene, options);
  for (const auto& [k0, k1] : slabs) fill.link(keysOf(k0, k1), k0, k1);
  std::vector<CellRun> runs;
  for (const auto& [k0, k1] : slabs)
    for (const CellRun& r : fill.fill(keysOf(k0, k1), k0, k1)) appendSolidRun(runs, r);
  ASSERT_EQ(runs.size(), whole.solidRuns.size()) << what << ", " << slabs.size() << " slabs";
  for (size_t r = 0; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].first, whole.solidRuns[r].first) << what << " run " << r;
    ASSERT_EQ(runs[r].count, whole.solidRuns[r].count) << what << " run " << r;
  }
  const FillReport& got = fill.report();
  EXPECT_EQ(got.rule, want.rule) << what;
  EXPECT_EQ(got.solidCells, want.solidCells) << what;
  EXPECT_EQ(got.enclosedCells, want.enclosedCells) << what;
  EXPECT_EQ(got.windingCells, want.windingCells) << what;
  EXPECT_EQ(got.emptyCells, want.emptyCells) << what;
  EXPECT_EQ(got.openEdges, want.openEdges) << what;
}

// Issue 45 #6: user bounds that cut a closed surface. The grid's faces are then not outside: the runs reaching them
// and the rows without a surface cell are decided by the surfaces outside the bounds too (DESIGN.md: primitives
// outside user bounds are still part of the scene). Each empty cell must be solid exactly when its centre is inside.
// `parts`: the closed, disjointly judged pieces whose union is the solid (CGAL's side test counts crossings' parity,
// which calls the overlap of two pieces outside); the scene by default.
void expectCutFillExact(const Scene& scene, const Box& bounds, std::array<uint32_t, 3> dims, OverlapMethod method,
                        const std::string& what, std::vector<const Scene*> parts = {}) {
  VoxelizeOptions o;
  o.dims = dims;
  o.bounds = bounds;
  o.method = method;
  Grid g = voxelizeScene(scene, o);
  const FillReport report = fillSolid(g, scene);
  expectRunsWellFormed(g);
  if (parts.empty()) parts.push_back(&scene);
  std::vector<std::unique_ptr<testing::ExactSide>> judges;
  for (const Scene* p : parts)
    judges.push_back(
        std::make_unique<testing::ExactSide>(std::vector<Triangle>(p->triangles.begin(), p->triangles.end())));
  const auto sideOf = [&](const Vec3& q) {
    int side = 1;
    for (const auto& j : judges) side = std::min(side, j->side(q));
    return side;
  };
  const std::vector<uint8_t> solid = solidMask(g);
  size_t c = 0, inside = 0;
  for (uint64_t key = 0; key < g.cellCount(); ++key) {
    while (c < g.cellKeys.size() && g.cellKeys[c] < key) ++c;
    if (c < g.cellKeys.size() && g.cellKeys[c] == key) continue;
    const int side = sideOf(cellCentre(g, key));
    ASSERT_NE(side, 0) << what;  // an empty cell's centre is off the surface
    ASSERT_EQ(bool(solid[key]), side < 0) << what << ": cell " << key << " (" << describeFill(report) << ")";
    inside += side < 0;
  }
  EXPECT_EQ(report.solidCells, inside) << what;
}

TEST(FillCutBounds, ClosedCubeCutByTheBoundsFillsItsInside) {
  const Scene cube = testing::boxScene(0, 1);
  for (const OverlapMethod m : {OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox}) {
    // The inputs: bounds inside the cube (no surface cell at all: every cell solid), partly outside.
    VoxelizeOptions o;
    o.dims = {8, 8, 8};
    o.bounds = Box{{0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}};
    o.method = m;
    Grid g = voxelizeScene(cube, o);
    ASSERT_EQ(g.occupiedCount(), 0u);
    const FillReport r = fillSolid(g, cube);
    EXPECT_EQ(r.solidCells, 512u);
    EXPECT_TRUE(r.boundsCut);
    EXPECT_NE(describeFill(r).find("the bounds cut the scene"), std::string::npos) << describeFill(r);
    expectCutFillExact(cube, *o.bounds, {8, 8, 8}, m, "inside");
    expectCutFillExact(cube, Box{{0.5, 0.5, 0.5}, {1.5, 1.5, 1.5}}, {8, 8, 8}, m, "corner");
    expectCutFillExact(cube, Box{{-0.5, 0.3, 0.3}, {1.5, 0.7, 0.7}}, {9, 5, 3}, m, "through");
  }
  // Bounds containing the cube are not cut: the flood fill, as before.
  Grid whole = voxelizeScene(cube, [] {
    VoxelizeOptions o;
    o.dims = {8, 8, 8};
    o.bounds = Box{{-0.5, -0.5, -0.5}, {1.5, 1.5, 1.5}};
    return o;
  }());
  EXPECT_EQ(fillSolid(whole, cube).rule, FillRule::Enclosed);
}

// Seeded: random closed meshes (boxes, rotated tetrahedra, two overlapping boxes) and random bounds cutting them,
// every conservative method, 1 to 32 cells per axis; the slabs' fill equal to the single grid's.
TEST(FillCutBounds, RandomClosedMeshesAndCuttingBounds) {
  std::mt19937 rng(45);
  std::uniform_real_distribution<double> u(0, 1);
  const int cases = testing::propertyRuns(kSanitized ? 12 : 40);
  for (int n = 0; n < cases; ++n) {
    Scene s, other;
    if (n % 3 == 0) {
      s = testing::boxScene(0.1 + 0.2 * u(rng), 0.6 + 0.3 * u(rng));
    } else if (n % 3 == 1) {
      s = testing::tetrahedronScene({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)},
                                    {u(rng), u(rng), u(rng)});
    } else {
      other = testing::boxScene(0.35 + 0.1 * u(rng), 0.9);
      s = testing::boxScene(0.1, 0.6);
      s.triangles.insert(s.triangles.end(), other.triangles.begin(), other.triangles.end());
    }
    Box b;
    for (int a = 0; a < 3; ++a) {
      const double x = u(rng), y = u(rng);
      b.lo.at(a) = std::min(x, y) - 0.2, b.hi.at(a) = std::max(x, y) + 0.05;
    }
    const std::array<uint32_t, 3> dims{1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32)};
    const OverlapMethod m = std::array{OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox}[n % 3];
    const std::string what = "case " + std::to_string(n);
    const Scene first = testing::boxScene(0.1, 0.6);
    expectCutFillExact(s, b, dims, m, what,
                       n % 3 == 2 ? std::vector<const Scene*>{&first, &other} : std::vector<const Scene*>{});
    VoxelizeOptions o;
    o.dims = dims;
    o.bounds = b;
    o.method = m;
    expectSlabFillEqualsFillSolid(voxelizeScene(s, o), s, rng, 4, {}, what);
  }
}

// Random occupancy near the percolation threshold: mazes of empty cells that wind up and down through many slabs,
// join in one slab what was apart in the ones below and reach the outside far from where they started. The slabs'
// flood must find the single grid's enclosed cells (and the dense reference's); it fails when a component's status
// is not carried across slab faces in both directions.
TEST(SlabFill, RandomMazesEqualTheSingleGridsFlood) {
  std::mt19937 rng(20261202);
  const Scene empty;  // no triangles: the Enclosed rule, which reads only the cells
  for (int trial = 0; trial < (kSanitized ? 12 : 60); ++trial) {
    Grid g;
    g.bounds = Box{{0, 0, 0}, {1, 1, 1}};
    g.dims = {2 + uint32_t(rng() % 14), 2 + uint32_t(rng() % 14), 2 + uint32_t(rng() % 40)};
    // Mostly near the threshold (empty cells percolate above about 31% of a cubic lattice), some far from it.
    const double density = trial % 5 == 0 ? 0.3 : 0.62 + 0.1 * double(rng() % 1000) / 1000;
    std::bernoulli_distribution occupied(density);
    for (uint64_t key = 0; key < g.cellCount(); ++key)
      if (occupied(rng)) g.cellKeys.push_back(key);
    g.cellStart.assign(g.cellKeys.size() + 1, 0);
    const std::string what = "trial " + std::to_string(trial);
    expectSlabFillEqualsFillSolid(g, empty, rng, 1 + uint32_t(trial % 4), {}, what);
    Grid reference = g;
    fillSolid(reference, empty);
    const std::vector<uint8_t> dense = referenceEnclosed(g), got = solidMask(reference);
    ASSERT_EQ(got, dense) << what;
  }
}

// Open and closed meshes (the WindingNumber rule with its hole caps, and the flood), spheres, in slabs of 1 to 3
// planes.
TEST(SlabFill, MeshesEqualTheSingleGridsFill) {
  std::mt19937 rng(7);
  Scene cup = testing::boxScene(0.2, 0.8);
  cup.triangles.erase(cup.triangles.begin() + 2, cup.triangles.begin() + 4);  // the top face (z = 0.8) removed
  Scene boxes = testing::boxScene(0.1, 0.45);
  for (const Triangle& t : testing::boxScene(0.3, 0.9).triangles) boxes.triangles.push_back(t);
  const Scene bunny = loadScene(seed("meshes/bun_zipper.ply"));
  Scene spheres;
  spheres.materials.push_back({});
  spheres.spheres.push_back({{0.35, 0.4, 0.5}, 0.25, {}, 0});
  spheres.spheres.push_back({{0.6, 0.55, 0.45}, 0.2, {}, 0});
  const std::pair<const char*, const Scene*> scenes[] = {
      {"cup", &cup}, {"two boxes", &boxes}, {"open bunny", &bunny}, {"spheres", &spheres}};
  for (const auto& [name, scene] : scenes) {
    for (const uint32_t n : {11u, kSanitized ? 24u : 47u}) {
      VoxelizeOptions o;
      o.dims = std::array<uint32_t, 3>{n, n + 2, n - 3};
      if (scene != &bunny) o.bounds = Box{{0, 0, 0}, {1, 1, 1}};
      const Grid grid = voxelizeScene(*scene, o);
      const std::string what = std::string(name) + " at " + std::to_string(n);
      expectSlabFillEqualsFillSolid(grid, *scene, rng, 3, {}, what);
      FillOptions flood;  // the cup's inside reaches the outside only through the planes above it
      flood.rule = FillRule::Enclosed;
      expectSlabFillEqualsFillSolid(grid, *scene, rng, 2, flood, what + ", flood");
    }
  }
}

// Slabs out of order, a fill before every plane was linked, or cells outside their slab are refused.
TEST(SlabFill, MisuseIsRefused) {
  Grid g;
  g.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  g.dims = {4, 4, 4};
  g.cellKeys = {5, 21, 37};
  const Scene empty;
  const std::span<const uint64_t> none;
  {
    SlabFill fill(g, empty, {});
    EXPECT_THROW(fill.link(none, 1, 2), Error);  // not from plane 0
    fill.link(std::span<const uint64_t>(g.cellKeys), 0, 3);
    EXPECT_THROW(fill.fill(none, 0, 4), Error);  // plane 3 never linked
  }
  {
    SlabFill fill(g, empty, {});
    const uint64_t outside[] = {40};  // plane 2
    EXPECT_THROW(fill.link(std::span<const uint64_t>(outside), 0, 2), Error);
  }
}

}  // namespace
}  // namespace vox
