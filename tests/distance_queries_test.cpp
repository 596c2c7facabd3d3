// Distances beyond the band: NearestPrimitive against brute force over every primitive (bit for bit, ties to the
// lowest id), the dense field against the --sdf band and brute force, either memory layout, and point queries with
// their closest points, NaN refused, cancellation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/nearest.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

// The bunny of 1k triangles, a ball and an ellipsoid beside it.
Scene dqScene() {
  Scene s = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  const Box b = *sceneBounds(s);
  Sphere ball;
  ball.center = b.hi + Vec3{0.1, 0, 0};
  ball.radius = 0.05;
  s.spheres.push_back(ball);
  Sphere ell = ball;
  ell.center = b.lo - Vec3{0.1, 0, 0};
  ell.transform = translation(ell.center) * scaling({1.5, 1, 0.7}) * translation(ell.center * -1.0);
  s.spheres.push_back(ell);
  return s;
}

double dqBruteDistance2(const Scene& s, const std::vector<EllipsoidShape>& shapes, const Vec3& p, int64_t* id) {
  double best = INFINITY;
  *id = -1;
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    const Triangle& tr = s.triangles[t];
    const double d2 = squaredDistanceToTriangle(tr.v[0], tr.v[1], tr.v[2], p);
    if (d2 < best) best = d2, *id = int64_t(t);
  }
  for (size_t e = 0; e < shapes.size(); ++e) {
    const Vec3 d = p - closestPointOnEllipsoid(shapes[e], p);
    if (dot(d, d) < best) best = dot(d, d), *id = int64_t(s.triangles.size() + e);
  }
  return best;
}

TEST(NearestPrimitive, EqualsBruteForceBitForBit) {
  const Scene s = dqScene();
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& sp : s.spheres) shapes.push_back(ellipsoidShape(sp));
  const NearestPrimitive nearest(s);
  const Box b = *sceneBounds(s);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  for (int n = 0; n < 3000; ++n) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p.at(a) = b.lo[a] + u(rng) * (b.hi[a] - b.lo[a]);
    if (n % 3 == 0) p = s.triangles[size_t(n) % s.triangles.size()].v[n % 3];  // on a vertex
    int64_t id;
    const double want = dqBruteDistance2(s, shapes, p, &id);
    const NearestHit hit = nearest.nearest(p);
    ASSERT_EQ(hit.squaredDistance, want) << n;
    if (want > 0) {
      EXPECT_EQ(hit.primitive, id) << n;
    }
    // A bound at the answer keeps it; one below gives nothing.
    EXPECT_EQ(nearest.nearest(p, want).squaredDistance, want);
    if (want > 0) {
      EXPECT_EQ(nearest.nearest(p, want * 0.999).primitive, -1);
    }
  }
  EXPECT_EQ(NearestPrimitive(Scene{}).nearest({0, 0, 0}).primitive, -1);
}

// The pruning's lower bound (plane and edge half-planes, triangleLowerBound) never skips a triangle whose computed
// distance is within the bound, at scales 1e-6 to 1e6, 1e6 from the origin, on needles and slivers, for points on
// vertices, on edges, in the plane and one ulp off it; and it does prune, or the test would prove nothing.
TEST(TriangleLowerBound, NeverSkipsATriangleWithinTheBoundAtAnyScale) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  size_t checked = 0, pruned = 0;
  for (const double scale : {1e-6, 1.0, 1e6})
    for (const double offset : {0.0, 1e6})
      for (int n = 0; n < 400; ++n) {
        const Vec3 origin{offset, -offset, 0.5 * offset};
        Triangle t;
        for (Vec3& v : t.v) v = origin + Vec3{u(rng), u(rng), u(rng)} * scale;
        if (n % 4 == 1) t.v[2] = t.v[0] + (t.v[1] - t.v[0]) * 0.5 + Vec3{0, 0, 1e-9 * scale};  // a needle
        if (n % 4 == 2) t.v[2] = t.v[0] + (t.v[1] - t.v[0]) * 0.3;                             // degenerate: a segment
        const TriangleLowerBound bound = triangleLowerBound(t);
        const Vec3 normal = cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
        std::vector<Vec3> points;
        for (int k = 0; k < 6; ++k) points.push_back(origin + Vec3{u(rng), u(rng), u(rng)} * (3 * scale));
        for (const Vec3& v : t.v) points.push_back(v);
        points.push_back((t.v[0] + t.v[1]) * 0.5);
        const Vec3 inPlane = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
        points.push_back(inPlane);
        points.push_back(inPlane + normal * (1e-300 / std::max(length(normal), 1e-300)));
        points.push_back({std::nextafter(inPlane.x, INFINITY), inPlane.y, inPlane.z});
        for (const Vec3& p : points) {
          const double d2 = squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], p);
          ASSERT_EQ(squaredDistanceToTriangleWithin(t, bound, p, d2), d2) << scale << " " << offset << " " << n;
          ++checked;
          if (d2 > 0) pruned += squaredDistanceToTriangleWithin(t, bound, p, 0.25 * d2) == INFINITY;
        }
      }
  EXPECT_GT(pruned, checked / 4) << "of " << checked;
}

// Searches seeded from any primitive, on a fan whose centre vertex six triangles share (ties to the lowest id), a
// mesh 1e6 from the origin with 1e-3 triangles, and a scene of needles: equal to brute force bit for bit.
TEST(NearestPrimitive, SeededSearchesEqualBruteForceOnFansFarScenesAndNeedles) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const double offset : {0.0, 1e6}) {
    Scene s;
    const Vec3 o{offset, offset, -offset};
    for (int k = 0; k < 6; ++k) {  // the fan: equidistant from points straight above its centre
      const double a0 = k * M_PI / 3, a1 = (k + 1) * M_PI / 3, r = 1e-3;
      s.triangles.push_back(
          {{o, o + Vec3{r * std::cos(a0), r * std::sin(a0), 0}, o + Vec3{r * std::cos(a1), r * std::sin(a1), 0}}});
    }
    for (int k = 0; k < 300; ++k) {  // needles and small triangles around it
      const Vec3 a = o + Vec3{u(rng), u(rng), u(rng)} * 4e-3, b = a + Vec3{u(rng), u(rng), u(rng)} * 1e-3;
      const Vec3 c = k % 2 ? a + (b - a) * 0.5 + Vec3{1e-12, 0, 0} : a + Vec3{u(rng), u(rng), u(rng)} * 1e-3;
      s.triangles.push_back({{a, b, c}});
    }
    std::vector<EllipsoidShape> shapes;
    const NearestPrimitive nearest(s);
    for (int n = 0; n < 2000; ++n) {
      Vec3 p = o + Vec3{u(rng), u(rng), u(rng)} * 6e-3;
      if (n % 4 == 0) p = o + Vec3{0, 0, 1e-4 * (1 + n % 7)};  // above the fan's centre: six ties
      if (n % 4 == 1) p = s.triangles[size_t(n) % s.triangles.size()].v[n % 3];
      int64_t id;
      const double want = dqBruteDistance2(s, shapes, p, &id);
      const NearestHit hit = nearest.nearestFrom(p, int64_t(n * 7919) % int64_t(s.triangles.size()));
      ASSERT_EQ(hit.squaredDistance, want) << offset << " " << n;
      ASSERT_EQ(hit.primitive, id) << offset << " " << n;
    }
  }
}

Grid dqFilledGrid(const Scene& s, std::array<uint32_t, 3> dims) {
  VoxelizeOptions o;
  o.dims = dims;
  Grid g = voxelizeScene(s, o);
  fillSolid(g, s);
  return g;
}

TEST(DenseSignedDistances, EqualTheBandAndBruteForceInEitherLayout) {
  const Scene s = dqScene();
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& sp : s.spheres) shapes.push_back(ellipsoidShape(sp));
  const Grid g = dqFilledGrid(s, {19, 14, 17});
  const auto [nx, ny, nz] = g.dims;
  std::vector<double> c(g.cellCount()), f(g.cellCount());
  denseSignedDistances(g, s, c, {uint64_t(ny) * nz, nz, 1});  // numpy's C order
  denseSignedDistances(g, s, f, {1, nx, uint64_t(nx) * ny});  // key order
  for (uint64_t key = 0; key < g.cellCount(); ++key) {
    const auto ijk = cellIndex(g.dims, key);
    const double value = c[(uint64_t(ijk[0]) * ny + ijk[1]) * nz + ijk[2]];
    ASSERT_EQ(value, f[key]) << key;
    int64_t id;
    ASSERT_EQ(std::fabs(value), std::sqrt(dqBruteDistance2(s, shapes, cellCentre(g, key), &id))) << key;
  }
  SdfOptions o;
  o.halfWidth = 2.5;
  const SdfBand band = signedDistanceBand(g, s, o);
  ASSERT_FALSE(band.keys.empty());
  for (size_t b = 0; b < band.keys.size(); ++b) EXPECT_EQ(f[band.keys[b]], band.values[b]) << band.keys[b];
  size_t negative = 0;
  for (double v : f) negative += v < 0;
  EXPECT_GT(negative, 0u);
}

TEST(PointDistances, SignedUnsignedClosestPointsNaNAndCancel) {
  const Scene s = dqScene();
  const Box b = *sceneBounds(s);
  const Vec3 mid = (b.lo + b.hi) * 0.5;
  const std::vector<double> pts = {mid.x, mid.y, mid.z, b.hi.x + 1, b.hi.y, b.hi.z, b.lo.x - 0.1, b.lo.y, b.lo.z};
  std::vector<double> d(3), ud(3), closest(9);
  std::vector<int64_t> prim(3);
  pointDistances(s, pts, true, {d, prim, closest});
  pointDistances(s, pts, false, {ud, prim, closest});
  const NearestPrimitive nearest(s);
  for (size_t i = 0; i < 3; ++i) {
    const Vec3 p{pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]};
    const NearestHit hit = nearest.nearest(p);
    EXPECT_EQ(prim[i], hit.primitive);
    EXPECT_EQ(ud[i], std::sqrt(hit.squaredDistance));
    EXPECT_EQ(std::fabs(d[i]), ud[i]);
    const Vec3 q{closest[3 * i], closest[3 * i + 1], closest[3 * i + 2]};
    EXPECT_NEAR(length(p - q), ud[i], 1e-12 * (1 + ud[i]));
  }
  EXPECT_LT(d[0], 0);  // the bunny's middle is inside
  EXPECT_GT(d[1], 0);
  // Many points, searched in Morton order with each bounded by the one before: the same answers as alone.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  std::vector<double> many(3 * 5000);
  for (size_t i = 0; i < many.size(); ++i) many[i] = b.lo[i % 3] + u(rng) * (b.hi[i % 3] - b.lo[i % 3]);
  std::vector<double> md(5000), mc(3 * 5000);
  std::vector<int64_t> mp(5000);
  pointDistances(s, many, false, {md, mp, mc});
  for (size_t i = 0; i < 5000; ++i) {
    const NearestHit hit = nearest.nearest({many[3 * i], many[3 * i + 1], many[3 * i + 2]});
    ASSERT_EQ(md[i], std::sqrt(hit.squaredDistance)) << i;
    ASSERT_EQ(mp[i], hit.primitive) << i;
  }
  std::vector<double> bad = pts;
  bad[4] = NAN;
  EXPECT_THROW(pointDistances(s, bad, false, {d, prim, closest}), InputError);
  DistanceQueryOptions cancel;
  cancel.progress = [](double) { return false; };
  EXPECT_THROW(pointDistances(s, pts, false, {d, prim, closest}, cancel), Error);
}

}  // namespace
}  // namespace vox
