// The occupied centres' signs (occupiedCentresInside): on closed meshes equal to CGAL's exact Side_of_triangle_mesh
// at every centre, also centres in face planes and on edge lines; on meshes with holes and flipped triangles equal to
// the generalized winding number summed over every triangle; the fallbacks (`center`, a soup) equal InsideTest.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "exact_side.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/centre_signs.h"
#include "vox/distance/queries.h"
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

// The generalized winding number summed over every triangle in long double (van Oosterom and Strackee), written
// apart from the library's: the judge of the signs where it is not within 1e-9 of the threshold.
long double judgeWinding(const Scene& s, const Vec3& q) {
  long double w = 0;
  for (const Triangle& t : s.triangles) {
    long double a[3], b[3], c[3];
    for (int i = 0; i < 3; ++i)
      a[i] = (long double)t.v[0][i] - q[i], b[i] = (long double)t.v[1][i] - q[i], c[i] = (long double)t.v[2][i] - q[i];
    const auto dot = [](const long double* x, const long double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
    const long double det =
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
    const long double la = std::sqrt(dot(a, a)), lb = std::sqrt(dot(b, b)), lc = std::sqrt(dot(c, c));
    const long double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    if (det != 0) w += 2 * std::atan2(det, den);
  }
  return w / (4 * std::numbers::pi_v<long double>);
}

// The invariants of issue 45 at one grid: the band equals the dense field at its cells, which equals Grid.distance's
// point query at every centre, bit for bit and sign included; the sign is the winding number's decision (inside
// where |w| >= 0.5, spheres aside) wherever |w| is not within 1e-9 of 0.5. Returns the cells judged.
size_t expectSignsAgree(const Scene& s, const VoxelizeOptions& o, double half, const std::string& what) {
  const Grid g = voxelizeScene(s, o);
  SdfOptions so;
  so.halfWidth = half;
  const SdfBand band = signedDistanceBand(g, s, so);
  const uint64_t nx = g.dims[0], ny = g.dims[1];
  std::vector<double> dense(g.cellCount());
  denseSignedDistances(g, s, dense, {1, nx, nx * ny});  // key order
  std::vector<double> points(3 * g.cellCount()), closest(3 * g.cellCount()), at(g.cellCount());
  std::vector<int64_t> prims(g.cellCount());
  for (uint64_t key = 0; key < g.cellCount(); ++key) {
    const Vec3 c = cellCentre(g, key);
    for (int a = 0; a < 3; ++a) points[3 * key + a] = c[a];
  }
  pointDistances(s, points, true, {at, prims, closest});
  for (uint64_t key = 0; key < g.cellCount(); ++key)
    EXPECT_EQ(std::bit_cast<uint64_t>(dense[key]), std::bit_cast<uint64_t>(at[key]))
        << what << ": cell " << key << " dense " << dense[key] << " point query " << at[key];
  for (size_t b = 0; b < band.keys.size(); ++b)
    EXPECT_EQ(std::bit_cast<uint64_t>(band.values[b]), std::bit_cast<uint64_t>(dense[band.keys[b]]))
        << what << ": band cell " << band.keys[b] << " " << band.values[b] << " dense " << dense[band.keys[b]];
  // Judged: every band cell and every 7th cell beyond it.
  size_t judged = 0, b = 0;
  for (uint64_t key = 0; key < g.cellCount(); ++key) {
    const bool inBand = b < band.keys.size() && band.keys[b] == key;
    b += inBand;
    if ((!inBand && key % 7 != 0) || dense[key] == 0) continue;
    const long double w = judgeWinding(s, cellCentre(g, key));
    if (std::fabs(std::fabs(w) - 0.5L) <= 1e-9L) continue;
    EXPECT_EQ(dense[key] < 0, std::fabs(w) >= 0.5L) << what << ": cell " << key << " w " << double(w);
    ++judged;
  }
  return judged;
}

// Issue 45 #6 and #7 with their own inputs: bounds cutting a closed cube (every cell inside), and `center` (and
// every other method) on a closed sphere mesh, whose band cells inside must all be negative.
TEST(SignInvariants, CutBoundsAndEveryMethodSignLikeThePointQuery) {
  const Scene cube = testing::boxScene(0, 1);
  VoxelizeOptions o;
  o.dims = {8, 8, 8};
  o.bounds = Box{{0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}};
  const Grid g = voxelizeScene(cube, o);
  SdfOptions wide;
  wide.halfWidth = 8;  // every cell: the nearest face lies 0.25 to 0.47 away, cells are 0.0625
  const SdfBand band = signedDistanceBand(g, cube, wide);
  ASSERT_EQ(band.keys.size(), 512u);
  for (const double v : band.values) EXPECT_LT(v, 0);
  expectSignsAgree(cube, o, 8, "cube inside the bounds");
  o.bounds = Box{{0.5, 0.5, 0.5}, {1.5, 1.5, 1.5}};
  expectSignsAgree(cube, o, 3, "cube cut at a corner");
  const Scene ball = testing::sphereMesh({0.5, 0.5, 0.5}, 0.4, 3);
  for (const OverlapMethod m : {OverlapMethod::Center, OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox}) {
    VoxelizeOptions b;
    b.resolution = 24;
    b.method = m;
    EXPECT_GT(expectSignsAgree(ball, b, 3, "sphere, method " + std::to_string(int(m))), 1000u);
  }
}

// Issue 45 #8: an open bowl (a hemisphere without its cap), where w is near 0.5 over the opening.
TEST(SignInvariants, OpenBowlSignsAreTheWindingNumbers) {
  const Scene bowl = testing::sphereMesh({0, 0, 0}, 1, 3, true, 0.0);
  ASSERT_GT(countOpenEdges(bowl.triangles), 0u);
  VoxelizeOptions o;
  o.dims = {32, 32, 22};
  o.bounds = Box{{-1.1, -1.1, -1.1}, {1.1, 1.1, 0.4}};
  EXPECT_GT(expectSignsAgree(bowl, o, 3, "bowl"), 3000u);
  const Scene shallow = testing::sphereMesh({0, 0, 0}, 1, 3, true, -0.5);
  o.dims = {29, 31, 17};
  expectSignsAgree(shallow, o, 5, "shallow bowl");
}

// Seeded property loop: closed, open, self-intersecting and partly flipped meshes; bounds containing, inside,
// cutting or outside the scene; every method; 1 to 32 cells per axis. VOX_PROPERTY_RUNS=N runs more.
TEST(SignInvariants, RandomMeshesBoundsMethodsAndResolutions) {
  std::mt19937 rng(4508);
  std::uniform_real_distribution<double> u(0, 1);
  const int runs = testing::propertyRuns(testing::kSanitized ? 8 : 36);
  for (int n = 0; n < runs; ++n) {
    Scene s;
    const Vec3 c{0.3 + 0.4 * u(rng), 0.3 + 0.4 * u(rng), 0.3 + 0.4 * u(rng)};
    switch (n % 6) {
      case 0:
        s = testing::boxScene(0.1 + 0.2 * u(rng), 0.6 + 0.3 * u(rng));
        break;
      case 1:
        s = testing::sphereMesh(c, 0.2 + 0.2 * u(rng), 1 + n % 2);
        break;
      case 2:
        s = testing::sphereMesh(c, 0.2 + 0.2 * u(rng), 2, true, 0.6 * u(rng) - 0.3);
        break;   // open
      case 3: {  // self-intersecting: a box through a sphere
        s = testing::sphereMesh(c, 0.3, 2);
        const Scene box = testing::boxScene(0.2 + 0.3 * u(rng), 0.8);
        s.triangles.insert(s.triangles.end(), box.triangles.begin(), box.triangles.end());
        break;
      }
      case 4: {  // a patch turned over: its seam is an oriented boundary
        s = testing::sphereMesh(c, 0.3, 2);
        for (size_t t = 0; t < s.triangles.size(); t += 5) std::swap(s.triangles[t].v[1], s.triangles[t].v[2]);
        break;
      }
      default:
        s = testing::tetrahedronScene({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)},
                                      {u(rng), u(rng), u(rng)});
    }
    VoxelizeOptions o;
    o.method =
        std::array{OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox, OverlapMethod::Center}[rng() % 4];
    o.dims = std::array<uint32_t, 3>{1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32)};
    const int boundsKind = int(rng() % 4);  // the scene's own, inside, cutting, outside
    if (boundsKind > 0) {
      Box b;
      for (int a = 0; a < 3; ++a) {
        const double x = u(rng), y = u(rng);
        const double lo = std::min(x, y), hi = std::max(x, y) + 0.02;
        if (boundsKind == 1) b.lo.at(a) = 0.4 + 0.1 * lo, b.hi.at(a) = 0.5 + 0.1 * hi;
        if (boundsKind == 2) b.lo.at(a) = lo - 0.3, b.hi.at(a) = hi;
        if (boundsKind == 3) b.lo.at(a) = 1.5 + lo, b.hi.at(a) = 1.6 + hi;
      }
      o.bounds = b;
    }
    expectSignsAgree(s, o, 1 + 4 * u(rng), "case " + std::to_string(n));
  }
}

TEST(CentreSigns, ProgressSaysStopAndItThrows) {
  const Scene bunny = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  const Grid g = csGrid(bunny, {64, 64, 64});
  EXPECT_THROW(occupiedCentresInside(g, bunny, [](double) { return false; }), Error);
}

}  // namespace
}  // namespace vox
