// Signed distances (libvox/src/distance): closest points against CGAL's exact kernel, ellipsoids against their
// optimality condition and a dense sampling, the --sdf band against brute force, and its signs against CGAL's
// Side_of_triangle_mesh (exact predicates) on closed meshes, including the cases flood fills and ray parity get wrong.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/squared_distance_3.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "exact_side.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/closest_point.h"
#include "vox/distance/sdf.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"
#include "vox/voxelize/winding_number.h"

namespace vox {
namespace {

using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;

// The exact distance from p to triangle (a, b, c), rounded once: CGAL's exact squared distance, then sqrt of its
// double (the square root adds half an ulp).
double exactTriangleDistance(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const auto point = [](const Vec3& v) { return Epeck::Point_3(v.x, v.y, v.z); };
  const Epeck::Point_3 q = point(p);
  if (CGAL::collinear(point(a), point(b), point(c))) {
    double best = INFINITY;
    for (const auto& [s, t] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const auto seg = s.x == t.x && s.y == t.y && s.z == t.z
                           ? CGAL::squared_distance(q, point(s))
                           : CGAL::squared_distance(q, Epeck::Segment_3(point(s), point(t)));
      best = std::min(best, std::sqrt(CGAL::to_double(seg)));
    }
    return best;
  }
  return std::sqrt(CGAL::to_double(CGAL::squared_distance(q, Epeck::Triangle_3(point(a), point(b), point(c)))));
}

double ourTriangleDistance(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  return std::sqrt(squaredDistanceToTriangle(a, b, c, p));
}

// The stated bound (docs/distance.md): |d - d_exact| <= 16 eps (d_exact + L) max(1, L / h), L the triangle's longest
// edge and h its smallest height: a sliver's plane is known only to about eps L / h, the bound grows with it.
double triangleBound(const Vec3& a, const Vec3& b, const Vec3& c, double exact) {
  const double edge = std::max({length(b - a), length(c - b), length(a - c)});
  const double twiceArea = length(cross(b - a, c - a));
  const double aspect = twiceArea > 0 ? std::max(1.0, edge * edge / twiceArea) : 1.0;
  return 16 * std::numeric_limits<double>::epsilon() * (exact + edge) * aspect;
}

TEST(DistanceTriangle, RandomAndOnFeaturesWithinTheBoundOfTheExactDistance) {
  std::mt19937 rng(38);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;  // in units of the bound
  for (double scale : {1e-6, 1.0, 1e6})
    for (double offset : {0.0, 1e6}) {
      for (int trial = 0; trial < 300; ++trial) {
        const Vec3 o{offset, offset, offset};
        const Vec3 a = o + Vec3{u(rng), u(rng), u(rng)} * scale, b = o + Vec3{u(rng), u(rng), u(rng)} * scale;
        Vec3 c = o + Vec3{u(rng), u(rng), u(rng)} * scale;
        if (trial % 25 == 0) c = a + (b - a) * 0.5;  // degenerate: a segment
        std::vector<Vec3> points;
        for (int k = 0; k < 4; ++k) points.push_back(o + Vec3{u(rng), u(rng), u(rng)} * (2 * scale));
        // On and one ulp off the vertices, an edge's midpoint and the centroid.
        for (const Vec3& v : {a, b, (a + b) * 0.5, (a + b + c) / 3.0}) {
          points.push_back(v);
          points.push_back({std::nextafter(v.x, INFINITY), v.y, std::nextafter(v.z, -INFINITY)});
        }
        for (const Vec3& p : points) {
          const double exact = exactTriangleDistance(a, b, c, p);
          const double ours = ourTriangleDistance(a, b, c, p);
          const double bound = triangleBound(a, b, c, exact);
          ASSERT_LE(std::fabs(ours - exact), bound) << "scale " << scale << " offset " << offset << " trial " << trial;
          if (bound > 0) worst = std::max(worst, std::fabs(ours - exact) / bound);
        }
      }
    }
  std::printf("[ info ] worst triangle distance error: %.3f of the bound\n", worst);
}

TEST(DistanceTriangle, EquidistantFromTwoTrianglesBothGiveTheSameDistance) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  const Vec3 a2{0, 0, 2}, b2{1, 0, 2}, c2{0, 1, 2};
  const Vec3 p{0.25, 0.25, 1};
  EXPECT_EQ(ourTriangleDistance(a, b, c, p), 1.0);
  EXPECT_EQ(ourTriangleDistance(a2, b2, c2, p), 1.0);
}

// A point of the ellipsoid's surface at parameters (theta, phi).
Vec3 ellipsoidPoint(const EllipsoidShape& s, double theta, double phi) {
  const double u[3] = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
  Vec3 x = s.center;
  for (int i = 0; i < 3; ++i) x = x + s.axes[i] * (s.semi[i] * u[i]);
  return x;
}

TEST(DistanceEllipsoid, ClosestPointsLieOnTheSurfaceAlongTheNormalAndBeatEverySample) {
  Sphere sphere;
  sphere.center = {0.3, -0.2, 0.1};
  sphere.radius = 0.7;
  sphere.transform = translation({1, 2, 3}) * rotation({1, 2, 0.5}, 37) * scaling({1.8, 0.6, 1.1});
  const EllipsoidShape shape = ellipsoidShape(sphere);
  EXPECT_FALSE(shape.isSphere);
  // The frame reproduces the transform: world centre and the semi-axes' product (the volume factor).
  EXPECT_NEAR(shape.semi.x * shape.semi.y * shape.semi.z, std::pow(0.7, 3) * 1.8 * 0.6 * 1.1, 1e-12);
  std::vector<Vec3> samples;
  for (int i = 0; i <= 300; ++i)
    for (int j = 0; j < 600; ++j) samples.push_back(ellipsoidPoint(shape, M_PI * i / 300, 2 * M_PI * j / 600));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int trial = 0; trial < 60; ++trial) {
    Vec3 p = shape.center + Vec3{u(rng), u(rng), u(rng)};
    if (trial % 10 == 0) p = shape.center + shape.axes[0] * 0.1;  // inside, on the longest axis
    if (trial % 10 == 1) p = shape.center;                        // the centre: several nearest points
    const Vec3 x = closestPointOnEllipsoid(shape, p);
    double implicit = 0;
    for (int i = 0; i < 3; ++i) implicit += std::pow(dot(x - shape.center, shape.axes[i]) / shape.semi[i], 2);
    EXPECT_NEAR(implicit, 1, 1e-13) << trial;
    const double d = length(p - x);
    double sampled = INFINITY;
    for (const Vec3& s : samples) sampled = std::min(sampled, length(p - s));
    EXPECT_LE(d, sampled + 1e-12) << trial;  // no sample is nearer
    EXPECT_GE(d, sampled - 2e-4) << trial;   // and the samples (spaced about 0.01) come near it
    EXPECT_EQ(
        insideEllipsoid(shape, p), implicit > 0 && [&] {
          double q = 0;
          for (int i = 0; i < 3; ++i) q += std::pow(dot(p - shape.center, shape.axes[i]) / shape.semi[i], 2);
          return q < 1;
        }());
  }
}

TEST(DistanceWinding, APointOneUlpInsideAFaceCountsInside) {
  const Scene box = testing::boxScene(0, 1);
  // Off the face's diagonal: a point within rounding of both a face and an edge of the surface may take either
  // sign (docs/distance.md), its distance then being below the rounding too.
  for (double z : {0.7, 0.25}) {
    const Vec3 inside{std::nextafter(0.0, 1.0), 0.5, z}, outside{-std::nextafter(0.0, 1.0), 0.5, z};
    EXPECT_NEAR(windingNumberExact({box.triangles.data(), box.triangles.size()}, inside), 1, 1e-9);
    EXPECT_NEAR(windingNumberExact({box.triangles.data(), box.triangles.size()}, outside), 0, 1e-9);
  }
  const Vec3 nearFace{1 - 0x1p-53, 0.3, 0.7};  // the largest double below 1 on x: inside
  EXPECT_NEAR(windingNumberExact({box.triangles.data(), box.triangles.size()}, nearFace), 1, 1e-9);
}

using testing::ExactSide;

Grid filledGrid(const Scene& scene, std::array<uint32_t, 3> dims, const Box* bounds = nullptr) {
  VoxelizeOptions o;
  o.dims = dims;
  if (bounds) o.bounds = *bounds;
  Grid grid = voxelizeScene(scene, o);
  fillSolid(grid, scene);
  return grid;
}

// Every band cell against brute force over all primitives (magnitude) and CGAL (sign); and no cell left out.
void expectBandExact(const Scene& scene, const Grid& grid, double halfWidth, const std::string& what) {
  SdfOptions o;
  o.halfWidth = halfWidth;
  const SdfBand band = signedDistanceBand(grid, scene, o);
  const ExactSide exact(std::vector<Triangle>(scene.triangles.begin(), scene.triangles.end()));
  double h = INFINITY;
  for (int a = 0; a < 3; ++a) h = std::min(h, (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a]);
  size_t b = 0, signErrors = 0;
  for (uint64_t key = 0; key < grid.cellCount(); ++key) {
    const Vec3 c = cellCentre(grid, key);
    double best = INFINITY;
    for (const Triangle& t : scene.triangles) best = std::min(best, ourTriangleDistance(t.v[0], t.v[1], t.v[2], c));
    const bool inBand = best <= halfWidth * h;
    const bool listed = b < band.keys.size() && band.keys[b] == key;
    ASSERT_EQ(inBand, listed) << what << ": cell " << key << " at distance " << best;
    if (!listed) continue;
    EXPECT_EQ(std::fabs(band.values[b]), best) << what << ": cell " << key;
    const int side = exact.side(c);
    if (best > 0 && (side < 0) != (band.values[b] < 0)) ++signErrors;
    ++b;
  }
  EXPECT_EQ(signErrors, 0u) << what;
}

TEST(SdfBand, BoxWithCentresInItsFacePlanesMatchesBruteForceAndExactSigns) {
  // Faces at 0.25 and 0.75 with cells of 0.125 centred on multiples of 0.0625 + 0.125 k: some centres lie exactly
  // in the faces' planes and on the lines of their edges.
  const Scene box = testing::boxScene(0.1875, 0.8125);
  const Box bounds{{0, 0, 0}, {1, 1, 1}};
  expectBandExact(box, filledGrid(box, {8, 8, 8}, &bounds), 3, "box");
  expectBandExact(box, filledGrid(box, {16, 16, 16}, &bounds), 2.5, "box 16");
}

Scene twoBoxes(double gap) {
  Scene s = testing::boxScene(0, 1);
  const Scene other = testing::boxScene(0, 1);
  for (Triangle t : other.triangles) {
    for (Vec3& v : t.v) v.x += 1 + gap;
    s.triangles.push_back(t);
  }
  return s;
}

TEST(SdfBand, TwoBoxesOneCellAndOneUlpApartKeepTheirSigns) {
  // OpenVDB #903: nearby parts get wrong signs from a flood fill's tracker.
  const Box bounds{{-0.5, -0.5, -0.5}, {2.75, 1.5, 1.5}};
  expectBandExact(twoBoxes(0.25), filledGrid(twoBoxes(0.25), {26, 16, 16}, &bounds), 3, "one cell apart");
  const double ulp = std::nextafter(1.0, 2.0) - 1;
  expectBandExact(twoBoxes(ulp), filledGrid(twoBoxes(ulp), {26, 16, 16}, &bounds), 3, "one ulp apart");
}

TEST(SdfBand, SlabThinnerThanACell) {
  Scene slab = testing::boxScene(0.2, 0.8);
  for (Triangle& t : slab.triangles)
    for (Vec3& v : t.v) v.z = v.z == 0.2 ? 0.5 : 0.51;  // 0.01 thick, cells 0.125
  const Box bounds{{0, 0, 0}, {1, 1, 1}};
  expectBandExact(slab, filledGrid(slab, {8, 8, 8}, &bounds), 3, "thin slab");
  expectBandExact(slab, filledGrid(slab, {8, 8, 80}, &bounds), 3, "thin slab, flat cells");
}

TEST(SdfBand, SpheresAndEllipsoidsAgainstTheirClosedForms) {
  Scene s;
  s.materials.push_back({});
  Sphere ball;
  ball.center = {0.5, 0.5, 0.5};
  ball.radius = 0.3;
  s.spheres.push_back(ball);
  Grid grid = filledGrid(s, {20, 20, 20});
  const SdfBand band = signedDistanceBand(grid, s);
  ASSERT_FALSE(band.keys.empty());
  for (size_t b = 0; b < band.keys.size(); ++b) {
    const Vec3 c = cellCentre(grid, band.keys[b]);
    EXPECT_NEAR(band.values[b], length(c - ball.center) - 0.3, 1e-15);
  }
  Scene e;
  e.materials.push_back({});
  Sphere ell = ball;
  ell.transform = translation({0.5, 0.5, 0.5}) * scaling({1.5, 1, 0.7}) * translation({-0.5, -0.5, -0.5});
  e.spheres.push_back(ell);
  const EllipsoidShape shape = ellipsoidShape(ell);
  const Grid eg = filledGrid(e, {20, 20, 20});
  const SdfBand eb = signedDistanceBand(eg, e);
  ASSERT_FALSE(eb.keys.empty());
  for (size_t b = 0; b < eb.keys.size(); ++b) {
    const Vec3 c = cellCentre(eg, eb.keys[b]);
    const double d = length(c - closestPointOnEllipsoid(shape, c));
    EXPECT_EQ(eb.values[b], insideEllipsoid(shape, c) ? -d : d);
  }
}

TEST(SdfBand, OpenMeshesTakeTheSignOfTheWindingNumber) {
  Scene open = testing::boxScene(0.2, 0.8);
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);  // one face missing
  Grid grid = filledGrid(open, {10, 10, 10});
  const SdfBand band = signedDistanceBand(grid, open);
  const WindingTree tree = buildWindingTree({open.triangles.data(), open.triangles.size()});
  size_t checked = 0;
  for (size_t b = 0; b < band.keys.size(); ++b) {
    if (findCell(grid, band.keys[b]) < 0) continue;  // empty cells follow the fill, tested by the fill's tests
    const Vec3 c = cellCentre(grid, band.keys[b]);
    const double w = windingNumberExact({open.triangles.data(), open.triangles.size()}, c);
    if (band.values[b] != 0) {
      EXPECT_EQ(band.values[b] < 0, std::fabs(w) >= kWindingThreshold) << b;
    }
    ++checked;
  }
  EXPECT_GT(checked, 0u);
}

TEST(SdfBand, BadHalfWidthsAndTheMemoryLimitAreRefused) {
  const Scene box = testing::boxScene(0.2, 0.8);
  Grid grid = filledGrid(box, {8, 8, 8});
  for (double bad : {0.0, -1.0, double(NAN), double(INFINITY), 65.0}) {
    SdfOptions o;
    o.halfWidth = bad;
    EXPECT_THROW(signedDistanceBand(grid, box, o), UsageError) << bad;
  }
  SdfOptions small;
  small.memoryLimitBytes = 1000;
  EXPECT_THROW(signedDistanceBand(grid, box, small), LimitError);
  SdfOptions cancel;
  cancel.progress = [](double) { return false; };
  EXPECT_THROW(signedDistanceBand(grid, box, cancel), Error);
}

TEST(SdfGridFile, DistancesAndFractionsRoundTripInVersion5AndNotInVersion3) {
  const Scene box = testing::boxScene(0.2, 0.8);
  Grid grid = filledGrid(box, {8, 8, 8});
  const std::string plain = encodeGridFile(box, grid);
  uint32_t version = 0;
  std::memcpy(&version, plain.data() + 8, 4);
  EXPECT_EQ(version, 3u);  // nothing new: the bytes earlier builds wrote
  const SdfBand band = signedDistanceBand(grid, box);
  grid.sdfHalfWidth = 3;
  grid.sdfKeys = band.keys;
  grid.sdfValues = band.values;
  grid.fractions.assign(grid.occupiedCount(), 0.5);
  const std::string bytes = encodeGridFile(box, grid);
  std::memcpy(&version, bytes.data() + 8, 4);
  EXPECT_EQ(version, 5u);  // the band's keys as runs (tests/grid_section_distances_test.cpp)
  const GridFile back = decodeGridFile(bytes, "t.vgrid");
  EXPECT_EQ(back.grid.sdfHalfWidth, 3);
  EXPECT_EQ(back.grid.sdfKeys, grid.sdfKeys);
  EXPECT_EQ(back.grid.sdfValues, grid.sdfValues);
  EXPECT_EQ(back.grid.fractions, grid.fractions);
  EXPECT_EQ(encodeGridFile(back.scene, back.grid), bytes);
  EXPECT_THROW(encodeGridFile(box, grid, 3), UsageError);
  // The same sections claimed by a version 3 header: refused.
  std::string old = bytes;
  const uint32_t three = 3;
  std::memcpy(old.data() + 8, &three, 4);
  EXPECT_THROW(decodeGridFile(old, "old.vgrid"), InputError);
  // Every truncation and a fraction outside [0, 1]: refused, never a crash.
  for (size_t cut = plain.size(); cut < bytes.size(); cut += 7)
    EXPECT_THROW(decodeGridFile(bytes.substr(0, cut), "cut.vgrid"), InputError);
  Grid bad = grid;
  bad.fractions[0] = 1.5;
  EXPECT_THROW(decodeGridFile(encodeGridFile(box, bad), "bad.vgrid"), InputError);
}

}  // namespace
}  // namespace vox
