// The band by scan conversion (libvox/src/distance/band_scan.h) against the boxes route of issue 38 and against
// brute force: the same cells and the same values, bit for bit, on the course's scenes, the 69k bunny, soups, open
// meshes, spheres and ellipsoids, and the adversarial cases (faces in cell-centre planes, two boxes one ulp apart,
// a slab thinner than a cell, needles and slivers, scenes 1e-6 to 1e6 in size and 1e7 from the origin).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "adversary.h"
#include "distance/band_scan.h"
#include "test_util.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace band_scan_test {

uint64_t bits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// Both routes on one grid (the library's entry is the scan): keys equal, values equal to the bit.
void expectRoutesEqual(const Scene& scene, const Grid& grid, double halfWidth, const std::string& what) {
  SdfOptions o;
  o.halfWidth = halfWidth;
  const SdfBand boxes = band::signedDistanceBand(grid, scene, o, band::Route::kBoxes);
  const SdfBand scan = band::signedDistanceBand(grid, scene, o, band::Route::kScan);
  ASSERT_EQ(boxes.keys, scan.keys) << what;
  ASSERT_EQ(boxes.values.size(), scan.values.size()) << what;
  size_t differ = 0;
  for (size_t b = 0; b < scan.values.size(); ++b) {
    if (bits(boxes.values[b]) == bits(scan.values[b])) continue;
    if (++differ <= 3)
      ADD_FAILURE() << what << ": cell " << scan.keys[b] << ": boxes " << boxes.values[b] << ", scan "
                    << scan.values[b];
  }
  EXPECT_EQ(differ, 0u) << what;
}

Grid gridAt(const Scene& scene, uint32_t resolution) {
  VoxelizeOptions o;
  o.resolution = resolution;
  return planGrid(scene, withCubicCells(scene, o));
}

Grid gridOn(const Box& bounds, std::array<uint32_t, 3> dims) {
  VoxelizeOptions o;
  o.bounds = bounds;
  o.dims = dims;
  Scene empty;
  empty.materials.push_back({});
  return planGrid(empty, o);
}

TEST(BandScan, CourseScenesMatchTheBoxesRoute) {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(testing::seed("6837/scenes")))
    if (entry.path().extension() == ".obj" || entry.path().extension() == ".txt") paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end());
  ASSERT_GT(paths.size(), 10u);
  size_t withBand = 0;
  for (const std::string& path : paths) {
    const Scene scene = loadScene(path);
    if (!sceneBounds(scene)) continue;  // planes only
    const bool big = scene.triangles.size() > 10000;
    for (const uint32_t res : {20u, 48u}) {
      if (big && (testing::kSanitized || res > 20)) continue;
      expectRoutesEqual(scene, gridAt(scene, res), 3, path + " at " + std::to_string(res));
    }
    ++withBand;
  }
  EXPECT_GT(withBand, 10u);
}

TEST(BandScan, TheOpenBunnyAt64To256MatchesTheBoxesRoute) {
  const Scene bunny = loadScene(testing::seed("meshes/bun_zipper.ply"));
  for (const uint32_t res : {64u, 128u, 256u}) {
    if (testing::kSanitized && res > 64) continue;
    expectRoutesEqual(bunny, gridAt(bunny, res), 3, "bunny at " + std::to_string(res));
  }
  expectRoutesEqual(bunny, gridAt(bunny, 40), 0.5, "bunny, half a cell");
  expectRoutesEqual(bunny, gridAt(bunny, 40), 10, "bunny, 10 cells");
}

// Every cell against the minimum over all primitives: the band holds exactly the cells within the half-width, each
// with that minimum's square root (the sign aside).
void expectBruteForce(const Scene& scene, const Grid& grid, double halfWidth, const std::string& what) {
  SdfOptions o;
  o.halfWidth = halfWidth;
  const SdfBand band = signedDistanceBand(grid, scene, o);
  double h = INFINITY;
  for (int a = 0; a < 3; ++a) h = std::min(h, (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a]);
  const double reach = halfWidth * h;
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& s : scene.spheres) shapes.push_back(ellipsoidShape(s));
  size_t b = 0;
  for (uint64_t key = 0; key < grid.cellCount(); ++key) {
    const Vec3 c = cellCentre(grid, key);
    double best = INFINITY;
    for (const Triangle& t : scene.triangles)
      best = std::min(best, squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], c));
    for (const EllipsoidShape& s : shapes) {
      const Vec3 d = c - closestPointOnEllipsoid(s, c);
      best = std::min(best, dot(d, d));
    }
    const bool inBand = best <= reach * reach;
    const bool listed = b < band.keys.size() && band.keys[b] == key;
    ASSERT_EQ(inBand, listed) << what << ": cell " << key;
    if (!listed) continue;
    ASSERT_EQ(bits(std::fabs(band.values[b])), bits(std::sqrt(best))) << what << ": cell " << key;
    ++b;
  }
}

TEST(BandScan, SoupsWithSpheresAndEllipsoidsMatchBruteForceAndTheBoxesRoute) {
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    const Scene soup = testing::randomScene(seed, 150, 0);
    const Scene mixed = testing::randomScene(seed + 10, 80, 5);
    const Box unit{{-0.1, -0.1, -0.1}, {1.1, 1.1, 1.1}};
    for (const double hw : {0.5, 3.0}) {
      expectBruteForce(soup, gridOn(unit, {18, 16, 14}), hw, "soup " + std::to_string(seed));
      expectBruteForce(mixed, gridOn(unit, {14, 18, 16}), hw, "mixed " + std::to_string(seed));
    }
    expectRoutesEqual(soup, gridOn(unit, {40, 37, 33}), 3, "soup " + std::to_string(seed));
    expectRoutesEqual(mixed, gridOn(unit, {33, 40, 37}), 2, "mixed " + std::to_string(seed));
  }
}

TEST(BandScan, OpenMeshesAndFacesInCellCentrePlanes) {
  Scene open = testing::boxScene(0.2, 0.8);
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  expectRoutesEqual(open, gridOn({{0, 0, 0}, {1, 1, 1}}, {10, 10, 10}), 3, "open box");
  // Faces at 0.1875 and 0.8125, cells of 0.125 centred on 0.0625 + 0.125 k: centres in the faces' planes and on
  // their edges' lines.
  const Scene box = testing::boxScene(0.1875, 0.8125);
  for (const uint32_t n : {8u, 16u, 31u}) {
    expectRoutesEqual(box, gridOn({{0, 0, 0}, {1, 1, 1}}, {n, n, n}), 3, "box " + std::to_string(n));
    expectBruteForce(box, gridOn({{0, 0, 0}, {1, 1, 1}}, {n, n, n}), 2.5, "box " + std::to_string(n));
  }
}

Scene boxPair(double gap) {
  Scene s = testing::boxScene(0, 1);
  for (Triangle t : testing::boxScene(0, 1).triangles) {
    for (Vec3& v : t.v) v.x += 1 + gap;
    s.triangles.push_back(t);
  }
  return s;
}

TEST(BandScan, TwoBoxesOneUlpApartAndASlabThinnerThanACell) {
  const Box bounds{{-0.5, -0.5, -0.5}, {2.75, 1.5, 1.5}};
  const double ulp = std::nextafter(1.0, 2.0) - 1;
  for (const double gap : {0.25, ulp, 0.0}) {
    expectRoutesEqual(boxPair(gap), gridOn(bounds, {26, 16, 16}), 3, "two boxes " + std::to_string(gap));
    expectBruteForce(boxPair(gap), gridOn(bounds, {26, 16, 16}), 3, "two boxes " + std::to_string(gap));
  }
  Scene slab = testing::boxScene(0.2, 0.8);
  for (Triangle& t : slab.triangles)
    for (Vec3& v : t.v) v.z = v.z == 0.2 ? 0.5 : 0.51;
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{8, 8, 8}, {8, 8, 80}, {33, 9, 70}}) {
    expectRoutesEqual(slab, gridOn({{0, 0, 0}, {1, 1, 1}}, dims), 3, "thin slab");
    expectBruteForce(slab, gridOn({{0, 0, 0}, {1, 1, 1}}, dims), 3, "thin slab");
  }
}

// Needles (one edge 1e-9 of the others, or two vertices one ulp apart), slivers (a vertex a hair off the opposite
// edge), points and segments among ordinary triangles, whose lower bounds are unusable or badly conditioned.
TEST(BandScan, NeedlesAndSliversMatchBruteForce) {
  Scene s = testing::boxScene(0.3, 0.7);
  const Vec3 a{0.21, 0.43, 0.55}, b{0.83, 0.61, 0.37};
  s.triangles.push_back({{a, b, a + Vec3{1e-9, 0, 0}}});                                             // needle
  s.triangles.push_back({{a, b, Vec3{std::nextafter(b.x, 2.0), b.y, b.z}}});                         // one ulp
  s.triangles.push_back({{a, b, (a + b) * 0.5 + Vec3{0, 1e-12, 0}}});                                // sliver
  s.triangles.push_back({{a, b, (a + b) * 0.5}});                                                    // a segment
  s.triangles.push_back({{b, b, b}});                                                                // a point
  s.triangles.push_back({{Vec3{0.1, 0.1, 0.9}, Vec3{0.9, 0.12, 0.9}, Vec3{0.5, 0.11, 0.9000001}}});  // flat and long
  const Box unit{{0, 0, 0}, {1, 1, 1}};
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{12, 12, 12}, {25, 17, 21}}) {
    expectRoutesEqual(s, gridOn(unit, dims), 3, "needles");
    expectBruteForce(s, gridOn(unit, dims), 3, "needles");
  }
}

// The adversary's triangles (in cell planes, collinear, points, tiny) on its grids, at scales 1e-6 to 1e6 and 1e7
// from the origin: the rounding allowance of the rows never drops a cell or a nearer triangle.
TEST(BandScan, AdversarialTrianglesAtEveryScaleMatchBruteForce) {
  const int runs = testing::propertyRuns(testing::kSanitized ? 4 : 12);
  for (const testing::Case& c : testing::kCases)
    for (int seed = 0; seed < runs; ++seed) {
      testing::Adversary adversary(uint32_t(seed) * 7919u + 1u, c);
      Scene scene;
      scene.materials.push_back({});
      for (int t = 0; t < 40; ++t) scene.triangles.push_back(adversary.triangle());
      const std::string what =
          "scale " + std::to_string(c.scale) + " offset " + std::to_string(c.offset) + " seed " + std::to_string(seed);
      std::array<uint32_t, 3> dims = adversary.dims();
      expectBruteForce(scene, gridOn(adversary.bounds(), dims), 3, what);
      for (uint32_t& n : dims) n *= 3;
      expectRoutesEqual(scene, gridOn(adversary.bounds(), dims), 2, what + ", cells a third");
      expectBruteForce(scene, gridOn(adversary.bounds(), dims), 1, what + ", cells a third");
    }
}

}  // namespace band_scan_test
}  // namespace vox
