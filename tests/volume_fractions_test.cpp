// Volume fractions: convex polyhedra cell for cell against CGAL's exact hull of the cell and the polyhedron; closed
// meshes and balls adding up (with the fill's solid cells) to their exact volumes; a mesh on the cell planes and the
// same mesh one ulp off; the refusals, cancellation, the memory limit and thread-count independence.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "test_util.h"
#include "volume/ball_box.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using VfKernel = CGAL::Exact_predicates_exact_constructions_kernel;
using VfPoint = VfKernel::Point_3;

double vfCellVolume(const Grid& g, uint64_t key) {
  const auto ijk = cellIndex(g.dims, key);
  const Box b = cellBox(g, ijk[0], ijk[1], ijk[2]);
  return (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
}

// The exact volume of a convex polyhedron (outward triangles) and a box: the convex hull, in CGAL's exact kernel, of
// the points of both that lie in both, the polyhedron's edges cut by the box's planes and the box's edges cut by
// the polyhedron's planes. Independent of the library: no divergence theorem, no perturbation.
double vfExactConvexBoxVolume(const Scene& poly, const Box& box) {
  const auto point = [](const Vec3& v) { return VfPoint(v.x, v.y, v.z); };
  std::vector<VfKernel::Plane_3> planes;
  for (const Triangle& t : poly.triangles) planes.emplace_back(point(t.v[0]), point(t.v[1]), point(t.v[2]));
  const VfPoint lo = point(box.lo), hi = point(box.hi);
  const auto inside = [&](const VfPoint& p) {
    for (int a = 0; a < 3; ++a)
      if (p[a] < lo[a] || p[a] > hi[a]) return false;
    for (const auto& h : planes)
      if (h.has_on_positive_side(p)) return false;
    return true;
  };
  std::vector<VfPoint> candidates;
  std::vector<VfKernel::Segment_3> boxEdges;
  for (int c = 0; c < 8; ++c) {
    const VfPoint p((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    candidates.push_back(p);
    for (int a = 0; a < 3; ++a)
      if (!(c & (1 << a))) {
        const int d = c | (1 << a);
        boxEdges.emplace_back(p,
                              VfPoint((d & 1) ? hi.x() : lo.x(), (d & 2) ? hi.y() : lo.y(), (d & 4) ? hi.z() : lo.z()));
      }
  }
  for (const Triangle& t : poly.triangles)
    for (int i = 0; i < 3; ++i) {
      const VfPoint a = point(t.v[i]), b = point(t.v[(i + 1) % 3]);
      candidates.push_back(a);
      for (int ax = 0; ax < 3; ++ax)
        for (const auto& v : {lo[ax], hi[ax]})
          if (a[ax] != b[ax] && (a[ax] - v) * (b[ax] - v) <= 0) {
            const VfKernel::FT s = (v - a[ax]) / (b[ax] - a[ax]);
            candidates.push_back(a + (b - a) * s);
          }
    }
  for (const auto& e : boxEdges)
    for (const auto& h : planes)
      if (const auto hit = CGAL::intersection(e, h))
        if (const VfPoint* p = boost::get<VfPoint>(&*hit)) candidates.push_back(*p);
  std::vector<VfPoint> points;
  for (const VfPoint& p : candidates)
    if (inside(p)) points.push_back(p);
  // Fewer than four points off one plane: no volume (convex_hull_3 wants a solid).
  bool solid = false;
  for (size_t i = 3; i < points.size() && !solid; ++i)
    for (size_t j = 1; j < i && !solid; ++j)
      for (size_t k = 1; k < j && !solid; ++k)
        solid = !CGAL::collinear(points[0], points[j], points[k]) &&
                CGAL::orientation(points[0], points[j], points[k], points[i]) != CGAL::COPLANAR;
  if (!solid) return 0;
  CGAL::Surface_mesh<VfPoint> hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  return CGAL::to_double(CGAL::Polygon_mesh_processing::volume(hull));
}

// The convex hull of `points` (doubles) as outward triangles, computed exactly: a rotated box whose corners were
// rounded is not exactly convex any more (its quads fold), its hull is.
Scene vfConvexHull(const std::vector<Vec3>& points) {
  std::vector<VfPoint> exact;
  for (const Vec3& v : points) exact.emplace_back(v.x, v.y, v.z);
  CGAL::Surface_mesh<VfPoint> hull;
  CGAL::convex_hull_3(exact.begin(), exact.end(), hull);
  Scene s;
  s.materials.push_back({});
  for (const auto f : hull.faces()) {
    Triangle t;
    int i = 0;
    for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      const VfPoint& p = hull.point(v);
      t.v[i++] = {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
    }
    s.triangles.push_back(t);
  }
  return s;
}

std::vector<Vec3> vfVertices(const Scene& s) {
  std::vector<Vec3> v;
  for (const Triangle& t : s.triangles) v.insert(v.end(), t.v.begin(), t.v.end());
  return v;
}

Scene vfTransformed(Scene s, const Mat4& m) {
  for (Triangle& t : s.triangles)
    for (Vec3& v : t.v) v = transformPoint(m, v);
  return s;
}

// An octahedron of outward triangles: centre c, half-diagonal r along the axes.
Scene vfOctahedron(const Vec3& c, double r) {
  Scene s;
  s.materials.push_back({});
  for (int sx = -1; sx <= 1; sx += 2)
    for (int sy = -1; sy <= 1; sy += 2)
      for (int sz = -1; sz <= 1; sz += 2) {
        Triangle t{{c + Vec3{sx * r, 0, 0}, c + Vec3{0, sy * r, 0}, c + Vec3{0, 0, sz * r}}};
        if (sx * sy * sz < 0) std::swap(t.v[1], t.v[2]);
        s.triangles.push_back(t);
      }
  return s;
}

Grid vfVoxelize(const Scene& s, std::array<uint32_t, 3> dims, std::optional<Box> bounds = std::nullopt) {
  VoxelizeOptions o;
  o.dims = dims;
  o.bounds = bounds;
  return voxelizeScene(s, o);
}

void vfExpectMatchesExact(const Scene& poly, const Grid& g, const std::string& what) {
  const std::vector<double> f = volumeFractions(g, poly);
  ASSERT_EQ(f.size(), g.cellKeys.size());
  double worst = 0;
  for (size_t c = 0; c < f.size(); ++c) {
    ASSERT_GE(f[c], 0) << what;
    ASSERT_LE(f[c], 1) << what;
    const auto ijk = cellIndex(g.dims, g.cellKeys[c]);
    const Box box = cellBox(g, ijk[0], ijk[1], ijk[2]);
    const double vol = vfCellVolume(g, g.cellKeys[c]);
    const double err = std::fabs(f[c] * vol - vfExactConvexBoxVolume(poly, box)) / vol;
    worst = std::max(worst, err);
    EXPECT_LE(err, 1e-12) << what << " cell " << ijk[0] << " " << ijk[1] << " " << ijk[2];
  }
  ::testing::Test::RecordProperty(what, std::to_string(worst));
}

TEST(VolumeFractions, ConvexPolyhedraMatchExactClip) {
  vfExpectMatchesExact(testing::boxScene(0.1, 0.9),
                       vfVoxelize(testing::boxScene(0.1, 0.9), {4, 4, 4}, Box{{0, 0, 0}, {1, 1, 1}}), "cube");
  const Scene tet =
      testing::tetrahedronScene({0.05, 0.1, 0.02}, {0.93, 0.2, 0.11}, {0.3, 0.88, 0.25}, {0.41, 0.37, 0.97});
  vfExpectMatchesExact(tet, vfVoxelize(tet, {5, 4, 6}), "tetrahedron");
  const Mat4 rotated = translation({0.5, 0.5, 0.5}) * rotation({1, 2, 3}, 37);
  const Scene rot = vfConvexHull(vfVertices(vfTransformed(testing::boxScene(-0.3, 0.3), rotated)));
  vfExpectMatchesExact(rot, vfVoxelize(rot, {6, 5, 7}), "rotated box");
  Mat4 shear = translation({2, -1, 0.5});
  shear.m[0][1] = 0.7;
  shear.m[2][0] = -0.4;
  shear.m[1][2] = 0.25;
  const Scene sheared = vfConvexHull(vfVertices(vfTransformed(testing::boxScene(0, 1), shear)));
  vfExpectMatchesExact(sheared, vfVoxelize(sheared, {7, 6, 5}), "sheared box");
  // Vertices on grid corners, edges through grid lines and faces through corners: the perturbation's cases.
  const Scene oct = vfOctahedron({0.5, 0.5, 0.5}, 0.25);
  vfExpectMatchesExact(oct, vfVoxelize(oct, {8, 8, 8}, Box{{0, 0, 0}, {1, 1, 1}}), "octahedron on corners");
  // Far from the origin and small: the translation to each cell keeps the digits.
  const Scene far =
      vfConvexHull(vfVertices(vfTransformed(tet, translation({1e6, -2e6, 3e5}) * scaling({1e-3, 1e-3, 1e-3}))));
  vfExpectMatchesExact(far, vfVoxelize(far, {5, 4, 6}), "offset tetrahedron");
}

// The mesh's signed volume, exactly (rationals), as a double.
double vfExactSignedVolume(const Scene& s) {
  CGAL::Gmpq sum = 0;
  for (const Triangle& t : s.triangles) {
    const CGAL::Gmpq ax = t.v[0].x, ay = t.v[0].y, az = t.v[0].z, bx = t.v[1].x, by = t.v[1].y, bz = t.v[1].z,
                     cx = t.v[2].x, cy = t.v[2].y, cz = t.v[2].z;
    sum += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx);
  }
  return CGAL::to_double(sum / 6);
}

// Fractions times cell volumes plus the fill's solid cells.
// `windingFill`: the fill decides by winding number, which keeps a closed cavity empty (the flood fill's Enclosed
// rule counts a cavity that no empty path reaches from outside as solid).
double vfTotalVolume(Grid& g, const Scene& s, bool windingFill = false) {
  FillOptions fo;
  if (windingFill) {
    fo.rule = FillRule::WindingNumber;
    fo.windingOnly = true;
  }
  fillSolid(g, s, fo);
  const std::vector<double> f = volumeFractions(g, s);
  double total = 0;
  for (size_t c = 0; c < f.size(); ++c) {
    EXPECT_GE(f[c], 0);
    EXPECT_LE(f[c], 1);
    total += f[c] * vfCellVolume(g, g.cellKeys[c]);
  }
  for (const CellRun& r : g.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) total += vfCellVolume(g, key);
  return total;
}

TEST(VolumeFractions, ClosedMeshesAddUpToTheirVolume) {
  for (const char* name : {"6837/scenes/bunny_1k.obj", "6837/scenes/cube.obj", "6837/scenes/diamond.obj"}) {
    const Scene s = importObj(testing::seed(name));
    ASSERT_EQ(countOpenEdges({s.triangles.data(), s.triangles.size()}), 0u) << name;
    const double exact = std::fabs(vfExactSignedVolume(s));
    for (const uint32_t res : {7u, 16u, 33u}) {
      VoxelizeOptions o;
      o.resolution = res;
      Grid g = voxelizeScene(s, o);
      EXPECT_NEAR(vfTotalVolume(g, s), exact, 1e-12 * exact) << name << " at " << res;
    }
  }
  // A hollow box (outer shell outward, inner shell inward) and two disjoint boxes.
  Scene hollow = testing::boxScene(0, 1);
  for (Triangle t : testing::boxScene(0.3, 0.6).triangles) {
    std::swap(t.v[1], t.v[2]);
    hollow.triangles.push_back(t);
  }
  Grid g = vfVoxelize(hollow, {9, 9, 9}, Box{{-0.05, -0.05, -0.05}, {1.05, 1.05, 1.05}});
  EXPECT_NEAR(vfTotalVolume(g, hollow, true), 1 - 0.027, 1e-12);
  // The same hollow box inside out: w is 0 or -1, and the volume the same.
  Scene inverted = hollow;
  for (Triangle& t : inverted.triangles) std::swap(t.v[1], t.v[2]);
  Grid gi = vfVoxelize(inverted, {9, 9, 9}, Box{{-0.05, -0.05, -0.05}, {1.05, 1.05, 1.05}});
  EXPECT_NEAR(vfTotalVolume(gi, inverted, true), 1 - 0.027, 1e-12);
}

// The value of every cell: its fraction, 1 when solid, 0 when empty.
// Issue 45 #6: user bounds cutting the mesh. The fractions plus the fill's solid cells add up to the exact volume of
// the solid inside the bounds: the fill's runs that reach the grid's faces, and its rows without a surface cell,
// count the surfaces outside the bounds.
TEST(VolumeFractions, BoundsCuttingTheMeshAddUpToTheVolumeInside) {
  const Scene cube = testing::boxScene(0, 1);
  const std::pair<Box, double> cases[] = {
      {Box{{0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}}, 0.125},  // inside: no surface cell
      {Box{{0.5, 0.5, 0.5}, {1.5, 1.5, 1.5}}, 0.125},        // a corner
      {Box{{0.5, 0.25, 0.5}, {1.5, 1.0, 1.0}}, 0.1875},      // two faces on the bounds' own
      {Box{{-1, -1, -1}, {-0.5, 2, 2}}, 0.0},                // outside
      {Box{{-0.25, 0.125, 0.375}, {0.5, 1.75, 0.625}}, 0.5 * 0.875 * 0.25}};
  for (const auto& [bounds, want] : cases) {
    Grid g = vfVoxelize(cube, {8, 8, 8}, bounds);
    EXPECT_NEAR(vfTotalVolume(g, cube, true), want, 1e-15) << bounds.lo.x << " " << bounds.lo.y;
  }
  // Seeded: random convex polyhedra, random bounds (cutting, inside or outside), 1 to 32 cells per axis.
  std::mt19937 rng(4545);
  std::uniform_real_distribution<double> u(0, 1);
  const int runs = testing::propertyRuns(testing::kSanitized ? 10 : 40);
  for (int n = 0; n < runs; ++n) {
    std::vector<Vec3> points;
    for (int p = 0; p < 4 + n % 9; ++p) points.push_back({u(rng), u(rng), u(rng)});
    const Scene poly = vfConvexHull(points);
    Box b;
    for (int a = 0; a < 3; ++a) {
      const double x = 1.4 * u(rng) - 0.2, y = 1.4 * u(rng) - 0.2;
      b.lo.at(a) = std::min(x, y), b.hi.at(a) = std::max(x, y) + 0.01;
    }
    const std::array<uint32_t, 3> dims{1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32), 1 + uint32_t(rng() % 32)};
    Grid g = vfVoxelize(poly, dims, b);
    const double want = vfExactConvexBoxVolume(poly, b);
    const double boxVolume = (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
    EXPECT_NEAR(vfTotalVolume(g, poly, true), want, 1e-12 * boxVolume) << "case " << n;
  }
}

std::vector<double> vfDenseFractions(const Scene& s, const std::array<uint32_t, 3>& dims, const Box& bounds) {
  Grid g = vfVoxelize(s, dims, bounds);
  fillSolid(g, s);
  const std::vector<double> f = volumeFractions(g, s);
  std::vector<double> dense(g.cellCount(), 0);
  for (size_t c = 0; c < f.size(); ++c) dense[g.cellKeys[c]] = f[c];
  for (const CellRun& r : g.solidRuns)
    for (uint64_t key = r.first; key < r.first + r.count; ++key) dense[key] = 1;
  return dense;
}

TEST(VolumeFractions, AlignedMeshAndOneUlpOff) {
  const Box bounds{{0, 0, 0}, {1, 1, 1}};
  const std::array<uint32_t, 3> dims{4, 4, 4};
  const Scene aligned = testing::boxScene(0.25, 0.75);
  const std::vector<double> base = vfDenseFractions(aligned, dims, bounds);
  for (uint64_t key = 0; key < base.size(); ++key) {
    const auto ijk = cellIndex(dims, key);
    const bool in = ijk[0] >= 1 && ijk[0] <= 2 && ijk[1] >= 1 && ijk[1] <= 2 && ijk[2] >= 1 && ijk[2] <= 2;
    EXPECT_EQ(base[key], in ? 1.0 : 0.0) << ijk[0] << " " << ijk[1] << " " << ijk[2];
  }
  // Each vertex moved one ulp along one axis, either way: a cell changes by at most that move times its face
  // area, over its volume (the move / the cell edge), plus 1e-12.
  for (int axis = 0; axis < 3; ++axis)
    for (const double to : {-1.0, 2.0}) {
      Scene moved = aligned;
      double move = 0;
      for (Triangle& t : moved.triangles)
        for (Vec3& v : t.v) {
          const double before = v[axis];
          v.at(axis) = std::nextafter(before, to);
          move = std::max(move, std::fabs(v[axis] - before));
        }
      const std::vector<double> f = vfDenseFractions(moved, dims, bounds);
      for (uint64_t key = 0; key < base.size(); ++key)
        EXPECT_LE(std::fabs(f[key] - base[key]), move / 0.25 + 1e-12) << "axis " << axis << " cell " << key;
    }
  // A cube touching the grid's bounds on every side, its faces on the outermost cell planes.
  const Scene whole = testing::boxScene(0, 1);
  for (const double v : vfDenseFractions(whole, dims, bounds)) EXPECT_EQ(v, 1.0);
}

TEST(VolumeFractions, BallBoxVolumeKnownShapes) {
  const double r = 1.3, pi = std::numbers::pi;
  const Vec3 c{0.1, -0.2, 0.3};
  const double ball = 4.0 / 3 * pi * r * r * r;
  const auto near = [](double got, double want, double scale) { EXPECT_NEAR(got, want, 1e-13 * scale) << want; };
  near(volume::ballBoxVolume(c, r, Box{c - Vec3{2, 2, 2}, c + Vec3{2, 2, 2}}), ball, ball);
  near(volume::ballBoxVolume(c, r, Box{c - Vec3{r, r, r}, c + Vec3{r, r, r}}), ball, ball);
  near(volume::ballBoxVolume(c, r, Box{c - Vec3{0, r, r}, c + Vec3{r, r, r}}), ball / 2, ball);
  near(volume::ballBoxVolume(c, r, Box{c, c + Vec3{r, r, r}}), ball / 8, ball);
  const double h = 0.2;  // a cap of height h
  near(volume::ballBoxVolume(c, r, Box{c + Vec3{r - h, -r, -r}, c + Vec3{r, r, r}}), pi * h * h * (3 * r - h) / 3,
       h * 4 * r * r);
  near(volume::ballBoxVolume(c, r, Box{c - Vec3{0.3, 0.2, 0.1}, c + Vec3{0.2, 0.3, 0.4}}), 0.5 * 0.5 * 0.5, 0.125);
  near(volume::diskRectArea(1, -1, 1, -1, 1), pi, pi);
  near(volume::diskRectArea(1, 0, 1, 0, 1), pi / 4, 1);
}

TEST(VolumeFractions, BallsAddUpToFourThirdsPiRCubed) {
  Scene s;
  s.materials.push_back({});
  s.spheres.push_back({{0.1, 0.2, 0.3}, 1.0, Mat4::identity(), 0});
  const double ball = 4.0 / 3 * std::numbers::pi;
  for (const uint32_t res : {5u, 20u, 64u}) {
    VoxelizeOptions o;
    o.resolution = res;
    Grid g = voxelizeScene(s, o);
    EXPECT_NEAR(vfTotalVolume(g, s), ball, 1e-12 * ball) << res;
  }
  // A rotation times a uniform scale is still a ball: radius 0.5 * 2.
  Scene t = s;
  t.spheres[0] = {{0, 0, 0}, 0.5, translation({0.1, 0.2, 0.3}) * rotation({1, 1, 0}, 30) * scaling({2, 2, 2}), 0};
  Grid g = vfVoxelize(t, {11, 12, 13});
  EXPECT_NEAR(vfTotalVolume(g, t), ball, 1e-12 * ball);
}

std::string vfRefusal(const Scene& s, OverlapMethod method = OverlapMethod::Exact) {
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 6, 6};
  o.method = method;
  const Grid g = voxelizeScene(s, o);
  try {
    volumeFractions(g, s);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "no UsageError";
}

TEST(VolumeFractions, Refusals) {
  Scene open = testing::boxScene(0, 1);
  open.triangles.pop_back();
  EXPECT_NE(vfRefusal(open).find("volume fractions need closed surfaces: the mesh has 3 open edges"), std::string::npos)
      << vfRefusal(open);
  Scene ellipsoid;
  ellipsoid.materials.push_back({});
  ellipsoid.spheres.push_back({{0, 0, 0}, 1, scaling({1, 2, 1}), 0});
  EXPECT_NE(vfRefusal(ellipsoid).find("sphere 0 is an ellipsoid"), std::string::npos) << vfRefusal(ellipsoid);
  Scene plane = testing::boxScene(0, 1);
  plane.planes.push_back({});
  EXPECT_NE(vfRefusal(plane).find("1 plane(s), which bound no finite volume"), std::string::npos);
  Scene flipped = testing::boxScene(0, 1);
  std::swap(flipped.triangles[0].v[1], flipped.triangles[0].v[2]);
  std::swap(flipped.triangles[1].v[1], flipped.triangles[1].v[2]);
  EXPECT_NE(vfRefusal(flipped).find("consistently oriented"), std::string::npos) << vfRefusal(flipped);
  Scene overlapping = testing::boxScene(0, 1);
  for (const Triangle& t : testing::boxScene(0.5, 1.5).triangles) overlapping.triangles.push_back(t);
  EXPECT_NE(vfRefusal(overlapping).find("winding number reaches 2"), std::string::npos) << vfRefusal(overlapping);
  EXPECT_NE(vfRefusal(testing::boxScene(0, 1), OverlapMethod::Center).find("not center"), std::string::npos);
  Scene balls;
  balls.materials.push_back({});
  balls.spheres.push_back({{0, 0, 0}, 1, Mat4::identity(), 0});
  balls.spheres.push_back({{1, 0, 0}, 1, Mat4::identity(), 0});
  EXPECT_NE(vfRefusal(balls).find("overlapping solids"), std::string::npos) << vfRefusal(balls);
}

TEST(VolumeFractions, CancelMemoryLimitAndThreads) {
  const Scene s = importObj(testing::seed("6837/scenes/bunny_1k.obj"));
  VoxelizeOptions o;
  o.resolution = 40;
  const Grid g = voxelizeScene(s, o);
  FractionOptions cancel;
  cancel.progress = [](double) { return false; };
  try {
    volumeFractions(g, s, cancel);
    ADD_FAILURE() << "not cancelled";
  } catch (const LimitError&) {
    ADD_FAILURE() << "LimitError";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cancelled"), std::string::npos);
  }
  FractionOptions tight;
  tight.memoryLimitBytes = 4096;
  EXPECT_THROW(volumeFractions(g, s, tight), LimitError);
  std::vector<double> one, two;
  tbb::task_arena(1).execute([&] { one = volumeFractions(g, s); });
  tbb::task_arena(2).execute([&] { two = volumeFractions(g, s); });
  EXPECT_EQ(one, two);
}

}  // namespace
}  // namespace vox
