// NearestPrimitive's four-wide tree, its float bounds certified by a rounding allowance: the same primitive and the
// same double as brute force over every primitive (ties to the lowest id) on the course's meshes, the 69k bunny's
// dense field at 64, a soup and an open mesh; and the allowance never pruning the true nearest for points on
// vertices, edges and faces and one ulp off them, at scales 1e-6, 1 and 1e6, at the origin and 1e6 from it, on
// needles, slivers and degenerate triangles.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "test_util.h"
#include "vox/distance/nearest.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

// The nearest primitive by brute force, in the frame the search uses (ties to the lowest id).
NearestHit nwBrute(const Scene& s, const std::vector<EllipsoidShape>& shapes, const Vec3& p) {
  NearestHit best;
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const Triangle& tr = s.triangles[t];
    const double d2 = squaredDistanceToTriangle(tr.v[0], tr.v[1], tr.v[2], p);
    if (d2 < best.squaredDistance) best = {d2, int64_t(t)};
  }
  for (size_t e = 0; e < shapes.size(); ++e) {
    const Vec3 d = p - closestPointOnEllipsoid(shapes[e], p);
    if (dot(d, d) < best.squaredDistance) best = {dot(d, d), int64_t(s.triangles.size() + e)};
  }
  return best;
}

// Points that test the rounding allowance on triangle t: its vertices, points on its edges and face, each also one
// ulp off along every axis, and points just off its plane.
void nwPointsOn(const Triangle& t, std::vector<Vec3>& out) {
  std::vector<Vec3> on(t.v.begin(), t.v.end());
  for (int e = 0; e < 3; ++e) on.push_back(t.v[e] + (t.v[(e + 1) % 3] - t.v[e]) * 0.375);
  on.push_back((t.v[0] + t.v[1] + t.v[2]) / 3.0);
  const Vec3 n = cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
  const double nn = length(n);
  for (const Vec3& p : on) {
    out.push_back(p);
    for (int a = 0; a < 3; ++a)
      for (const double dir : {-INFINITY, INFINITY}) {
        Vec3 q = p;
        q.at(a) = std::nextafter(p[a], dir);
        out.push_back(q);
      }
    if (nn > 0) out.push_back(p + n * (1e-9 * length(t.v[1] - t.v[0]) / nn));
  }
}

void nwExpectBrute(const Scene& s, const std::vector<Vec3>& points, const std::string& what) {
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& sp : s.spheres) shapes.push_back(ellipsoidShape(sp));
  const NearestPrimitive nearest(s);
  const int64_t n = int64_t(nearest.primitiveCount());
  for (size_t i = 0; i < points.size(); ++i) {
    const NearestHit want = nwBrute(s, shapes, points[i]);
    const NearestHit hit = nearest.nearest(points[i]);
    ASSERT_EQ(hit.squaredDistance, want.squaredDistance) << what << " point " << i;
    ASSERT_EQ(hit.primitive, want.primitive) << what << " point " << i;
    const NearestHit seeded = nearest.nearestFrom(points[i], int64_t(i * 7919) % std::max<int64_t>(n, 1));
    ASSERT_EQ(seeded.squaredDistance, want.squaredDistance) << what << " seeded point " << i;
    ASSERT_EQ(seeded.primitive, want.primitive) << what << " seeded point " << i;
    if (want.squaredDistance > 0) {  // a bound just below the answer finds nothing, one equal to it the answer
      EXPECT_EQ(nearest.nearest(points[i], std::nextafter(want.squaredDistance, 0.0)).primitive, -1) << what << i;
      EXPECT_EQ(nearest.nearest(points[i], want.squaredDistance).primitive, want.primitive) << what << i;
    }
  }
}

// Random points over the scene's box and beyond it, and the adversarial points of every tenth triangle.
std::vector<Vec3> nwPoints(const Scene& s, int count, uint64_t seed) {
  const Box b = *sceneBounds(s);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 1.3);
  std::vector<Vec3> points;
  const Vec3 e = b.hi - b.lo;
  for (int k = 0; k < count; ++k) points.push_back(b.lo + Vec3{e.x * u(rng), e.y * u(rng), e.z * u(rng)});
  for (size_t t = 0; t < s.triangles.size(); t += std::max<size_t>(1, s.triangles.size() / 40))
    nwPointsOn(s.triangles[t], points);
  return points;
}

TEST(NearestPrimitiveWide, EqualsBruteForceOnCourseMeshesSoupsAndOpenMeshes) {
  for (const char* mesh : {"6837/scenes/bunny_200.obj", "6837/scenes/bunny_1k.obj", "6837/scenes/cube.obj",
                           "6837/scenes/diamond.obj", "6837/scenes/vase.obj", "6837/scenes/6.837.obj"}) {
    const Scene s = importObj(testing::seed(mesh));
    nwExpectBrute(s, nwPoints(s, 600, 3), mesh);
  }
  const Scene soup = testing::randomScene(9, 400, 6);  // degenerate and tiny triangles, spheres and ellipsoids
  nwExpectBrute(soup, nwPoints(soup, 1500, 4), "soup");
  Scene open = importObj(testing::seed("6837/scenes/bunny_1k.obj"));  // the bunny's upper half: an open mesh
  const Box ob = *sceneBounds(open);
  std::erase_if(open.triangles, [&](const Triangle& t) { return t.v[0].y < 0.5 * (ob.lo.y + ob.hi.y); });
  nwExpectBrute(open, nwPoints(open, 1500, 5), "open");
}

// Needles, slivers, degenerate triangles (segments and points) and a fan of shared vertices, at every scale and
// offset: the allowance must cover the float conversions relative to the tree's origin and the double route's own
// rounding, so no point on or one ulp off a primitive loses its nearest.
TEST(NearestPrimitiveWide, AllowanceNeverPrunesTheNearestAtAnyScale) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const double scale : {1e-6, 1.0, 1e6})
    for (const double offset : {0.0, 1e6}) {
      const Vec3 o{offset, -offset, 0.5 * offset};
      Scene s;
      for (int k = 0; k < 160; ++k) {
        const Vec3 a = o + Vec3{u(rng), u(rng), u(rng)} * scale;
        const Vec3 b = a + Vec3{u(rng), u(rng), u(rng)} * (0.3 * scale);
        Vec3 c = a + Vec3{u(rng), u(rng), u(rng)} * (0.3 * scale);
        if (k % 5 == 1) c = a + (b - a) * 0.5 + Vec3{0, 0, 1e-9 * scale};   // a needle
        if (k % 5 == 2) c = a + (b - a) * 0.3;                              // a segment
        if (k % 5 == 3) c = a + (b - a) * 1e-7 + Vec3{0, 1e-4 * scale, 0};  // a sliver
        s.triangles.push_back({{a, b, k % 17 == 4 ? a : c}});               // and some points
      }
      for (int k = 0; k < 6; ++k) {  // a fan around o: six ties above its centre
        const double a0 = k * M_PI / 3, a1 = (k + 1) * M_PI / 3, r = 0.2 * scale;
        s.triangles.push_back(
            {{o, o + Vec3{r * std::cos(a0), r * std::sin(a0), 0}, o + Vec3{r * std::cos(a1), r * std::sin(a1), 0}}});
      }
      std::vector<Vec3> points;
      for (const Triangle& t : s.triangles) nwPointsOn(t, points);
      for (int k = 0; k < 300; ++k) points.push_back(o + Vec3{u(rng), u(rng), u(rng)} * (1.5 * scale));
      for (int k = 1; k < 8; ++k) points.push_back(o + Vec3{0, 0, 1e-3 * k * scale});
      const std::string what = "scale " + std::to_string(scale) + " offset " + std::to_string(offset);
      nwExpectBrute(s, points, what);
      // The same in the scene's power-of-two frame, as Grid.distance searches it.
      const PowerOfTwoFrame frame = sceneFrame(s);
      const Scene framed = sceneInFrame(s, frame);
      std::vector<Vec3> framedPoints;
      for (const Vec3& p : points) framedPoints.push_back(frame.toFrame(p));
      nwExpectBrute(framed, framedPoints, what + " framed");
    }
}

// Points far beyond float range from the scene (searched without float pruning) and a scene of one triangle.
TEST(NearestPrimitiveWide, FarPointsAndTinyScenes) {
  Scene s = importObj(testing::seed("6837/scenes/bunny_200.obj"));
  std::vector<Vec3> points{{1e30, 0, 0}, {-1e19, 1e19, 3}, {0, 0, 1e150}, {1e18, 1e18, 1e18}};
  nwExpectBrute(s, points, "far");
  Scene one;
  one.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}});
  nwPointsOn(one.triangles[0], points);
  nwExpectBrute(one, points, "one triangle");
}

// Regions as the dense field's bricks make them: a centre, a radius and the bound `upper` from the centre's own
// nearest. Every point of the region, searched from its frontier, gets brute force's primitive and double, on
// regions around vertices, edges and faces and one ulp off, at every scale and offset; and a bound set below the
// truth loses some answers, so the comparison can see a frontier that drops a subtree it needs.
size_t nwFrontierMismatches(const Scene& s, uint64_t seed, double shrinkUpper) {
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& sp : s.spheres) shapes.push_back(ellipsoidShape(sp));
  const NearestPrimitive nearest(s);
  const int64_t n = int64_t(nearest.primitiveCount());
  const Box b = *sceneBounds(s);
  const double size = length(b.hi - b.lo);
  std::vector<Vec3> centres = nwPoints(s, 40, seed);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  NearestPrimitive::Frontier frontier;
  size_t mismatches = 0;
  for (size_t c = 0; c < centres.size(); c += 17) {
    const Vec3 centre = centres[c];
    const double radius = std::array{0.0, 1e-9, 1e-3, 0.02, 0.2}[c % 5] * size;
    const double upper = std::sqrt(nearest.nearest(centre).squaredDistance) + radius;
    nearest.gather(centre, radius, upper * shrinkUpper, 4 + c % 29, frontier);
    std::vector<Vec3> points{centre};
    for (int k = 0; k < 12; ++k) {  // inside the ball, some on its rim
      const Vec3 d{u(rng), u(rng), u(rng)};
      const double l = length(d);
      if (l > 0) points.push_back(centre + d * (radius * (k % 3 == 0 ? 1 - 0x1p-30 : std::fabs(u(rng))) / l));
    }
    for (const Vec3& near : centres)  // the adversarial points of other triangles that fall in the region
      if (length(near - centre) < radius) points.push_back(near);
    for (size_t i = 0; i < points.size(); ++i) {
      const NearestHit want = nwBrute(s, shapes, points[i]);
      const NearestHit hit = nearest.nearestFrom(points[i], int64_t(i * 7919 + c) % std::max<int64_t>(n, 1), frontier);
      mismatches += hit.squaredDistance != want.squaredDistance || hit.primitive != want.primitive;
    }
  }
  return mismatches;
}

TEST(NearestPrimitiveWide, FrontierSearchesEqualBruteForceInEveryRegion) {
  for (const char* mesh : {"6837/scenes/bunny_1k.obj", "6837/scenes/cube.obj", "6837/scenes/vase.obj"}) {
    const Scene s = importObj(testing::seed(mesh));
    EXPECT_EQ(nwFrontierMismatches(s, 7, 1.0), 0u) << mesh;
  }
  const Scene soup = testing::randomScene(9, 400, 6);
  EXPECT_EQ(nwFrontierMismatches(soup, 8, 1.0), 0u) << "soup";
  for (const double scale : {1e-6, 1.0, 1e6})
    for (const double offset : {0.0, 1e6}) {
      Scene s = importObj(testing::seed("6837/scenes/bunny_200.obj"));
      for (Triangle& t : s.triangles)
        for (Vec3& v : t.v) v = v * scale + Vec3{offset, -offset, 0.5 * offset};
      EXPECT_EQ(nwFrontierMismatches(s, 9, 1.0), 0u) << scale << " " << offset;
      const PowerOfTwoFrame frame = sceneFrame(s);
      EXPECT_EQ(nwFrontierMismatches(sceneInFrame(s, frame), 10, 1.0), 0u) << scale << " " << offset << " framed";
    }
  const Scene bunny = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  EXPECT_GT(nwFrontierMismatches(bunny, 7, 0.5), 0u) << "a bound below the truth must lose answers";
}

// The 69k bunny's dense field at 64 (which searches cell after cell from the one before's nearest): every cell of
// the --sdf band equal to the band's value, and a sample of cells of every kind equal to brute force.
TEST(NearestPrimitiveWide, BunnyDenseFieldEqualsTheBandAndBruteForce) {
  const Scene s = loadScene(testing::seed("meshes/bun_zipper.ply"));
  VoxelizeOptions o;
  o.resolution = 64;
  o = withCubicCells(s, o);
  Grid g = voxelizeScene(s, o);
  fillSolid(g, s);
  std::vector<double> field(g.cellCount());
  denseSignedDistances(g, s, field, {1, g.dims[0], uint64_t(g.dims[0]) * g.dims[1]});  // key order
  SdfOptions so;
  so.halfWidth = 3;
  const SdfBand band = signedDistanceBand(g, s, so);
  ASSERT_GT(band.keys.size(), 1000u);
  for (size_t b = 0; b < band.keys.size(); ++b) ASSERT_EQ(field[band.keys[b]], band.values[b]) << band.keys[b];
  const NearestPrimitive nearest(s);
  const std::vector<EllipsoidShape> none;
  std::mt19937_64 rng(23);
  for (int n = 0; n < 150; ++n) {
    const uint64_t key = rng() % g.cellCount();
    const Vec3 c = cellCentre(g, key);
    const NearestHit want = nwBrute(s, none, c);
    const NearestHit hit = nearest.nearestFrom(c, int64_t(rng() % s.triangles.size()));
    ASSERT_EQ(hit.squaredDistance, want.squaredDistance) << n;
    ASSERT_EQ(hit.primitive, want.primitive) << n;
    ASSERT_EQ(std::fabs(field[key]), std::sqrt(want.squaredDistance)) << key;
  }
}

}  // namespace
}  // namespace vox
