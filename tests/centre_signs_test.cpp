// The occupied centres' signs (occupiedCentresInside): on closed meshes equal to CGAL's exact Side_of_triangle_mesh
// at every centre, also centres in face planes and on edge lines; on meshes with holes and flipped triangles equal to
// the generalized winding number summed over every triangle; the fallbacks (`center`, a soup) equal InsideTest.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "exact_side.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/centre_signs.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/voxelize.h"
#include "vox/voxelize/winding_number.h"

namespace vox {
namespace {

Grid csGrid(const Scene& s, std::array<uint32_t, 3> dims, OverlapMethod method = OverlapMethod::Exact,
            const Box* bounds = nullptr) {
  VoxelizeOptions o;
  o.dims = dims;
  o.method = method;
  if (bounds) o.bounds = *bounds;
  return voxelizeScene(s, o);
}

TEST(CentreSigns, ClosedMeshesEqualCgalsExactSideAtEveryCentre) {
  const Scene bunny = importObj(testing::seed("6837/scenes/bunny_5k.obj"));
  ASSERT_EQ(countOpenEdges(bunny.triangles), 0u);
  const testing::ExactSide exact({bunny.triangles.begin(), bunny.triangles.end()});
  size_t compared = 0, inside = 0;
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{23, 17, 19}, {64, 64, 50}}) {
    const Grid g = csGrid(bunny, dims);
    const std::vector<uint8_t> signs = occupiedCentresInside(g, bunny);
    ASSERT_EQ(signs.size(), g.occupiedCount());
    for (size_t c = 0; c < signs.size(); ++c) {
      const int side = exact.side(cellCentre(g, g.cellKeys[c]));
      if (side == 0) continue;  // on the surface: its distance is 0, unsigned
      ASSERT_EQ(bool(signs[c]), side < 0) << c;
      ++compared, inside += signs[c];
    }
  }
  EXPECT_GT(inside, compared / 5);
  EXPECT_LT(inside, compared);
  // A box whose faces lie in planes of cell centres and whose edges lie on rows' lines.
  const Scene box = testing::boxScene(0.1875, 0.8125);
  const Box bounds{{0, 0, 0}, {1, 1, 1}};
  const testing::ExactSide boxSide({box.triangles.begin(), box.triangles.end()});
  for (const uint32_t n : {8u, 16u}) {
    const Grid g = csGrid(box, {n, n, n}, OverlapMethod::Exact, &bounds);
    const std::vector<uint8_t> signs = occupiedCentresInside(g, box);
    for (size_t c = 0; c < signs.size(); ++c) {
      const int side = boxSide.side(cellCentre(g, g.cellKeys[c]));
      if (side != 0) {
        ASSERT_EQ(bool(signs[c]), side < 0) << n << " " << c;
      }
    }
  }
}

// The 1k bunny with holes punched and a patch of triangles turned over: its oriented boundary is the holes' rims and
// the patch's seam, which the caps close.
TEST(CentreSigns, HolesAndFlippedTrianglesFollowTheWindingNumber) {
  Scene s = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  HugeVector<Triangle> kept;
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    Triangle tri = s.triangles[t];
    if (t % 97 == 5) continue;                               // holes
    if (t >= 300 && t < 340) std::swap(tri.v[1], tri.v[2]);  // flipped
    kept.push_back(tri);
  }
  s.triangles = std::move(kept);
  ASSERT_GT(countOpenEdges(s.triangles), 0u);
  size_t compared = 0, inside = 0;
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{20, 20, 16}, {41, 37, 33}}) {
    const Grid g = csGrid(s, dims);
    const std::vector<uint8_t> signs = occupiedCentresInside(g, s);
    for (size_t c = 0; c < signs.size(); ++c) {
      const double w = windingNumberExact(s.triangles, cellCentre(g, g.cellKeys[c]));
      if (std::abs(std::abs(w) - 0.5) < 1e-3) continue;  // the caps' tree errs by about that
      ASSERT_EQ(bool(signs[c]), std::abs(w) >= 0.5) << c << " w " << w;
      ++compared, inside += signs[c];
    }
  }
  EXPECT_GT(compared, 2000u);
  EXPECT_GT(inside, compared / 10);
}

TEST(CentreSigns, CentreGridsAndSoupsFallBackToTheInsideTest) {
  const Scene bunny = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  Scene soup;  // 100 separate triangles: 100 boundaries, more than the caps take
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int t = 0; t < 100; ++t) {
    const Vec3 a{u(rng), u(rng), u(rng)};
    soup.triangles.push_back({{a, a + Vec3{0.1, 0, 0}, a + Vec3{0, 0.1, 0.05}}});
  }
  for (const auto& [scene, method] : {std::pair<const Scene*, OverlapMethod>{&bunny, OverlapMethod::Center},
                                      std::pair<const Scene*, OverlapMethod>{&soup, OverlapMethod::Exact}}) {
    const Grid g = csGrid(*scene, {24, 24, 24}, method);
    const InsideTest test(*scene);
    const std::vector<uint8_t> signs = occupiedCentresInside(g, *scene);
    for (size_t c = 0; c < signs.size(); ++c) ASSERT_EQ(bool(signs[c]), test.inside(cellCentre(g, g.cellKeys[c]))) << c;
  }
}

TEST(CentreSigns, ProgressSaysStopAndItThrows) {
  const Scene bunny = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  const Grid g = csGrid(bunny, {64, 64, 64});
  EXPECT_THROW(occupiedCentresInside(g, bunny, [](double) { return false; }), Error);
}

}  // namespace
}  // namespace vox
