// The level surface of the distance band (vox/export/level_surface.h): closed, two-manifold (every edge in two
// faces of opposite directions, every vertex's faces one fan), oriented outward (signed volume near the fractions'
// exact total), no zero-area face, no duplicate vertex, every vertex within the stated bound of the level by the
// exact point distances; on the course's meshes, the open 69k bunny, a triangle soup, boxes one ulp apart, a slab
// thinner than a cell, flipped normals, a 1x1x1 grid, bounds cutting the surface, levels != 0, and random meshes
// (RapidCheck; RC_PARAMS="max_success=2000" build/vox_tests --gtest_filter='LevelSurface*' for a longer run).
#include "vox/export/level_surface.h"

#include <gtest/gtest.h>
#include <rapidcheck.h>
#include <tbb/task_arena.h>
#include <rapidcheck/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/core/scene.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::kSanitized;
using testing::seed;

Vec3 sub(const Vec3& a, const Vec3& b) { return a - b; }

// Empty when the mesh is a closed, consistently oriented 2-manifold with distinct vertices, every vertex used and
// no zero-area face; otherwise the first defect.
std::string topologyDefect(const VoxelMesh& m) {
  if (!m.isTriangleMesh()) return "not triangles";
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> around(m.vertexCount());  // (next, previous) per face
  for (size_t f = 0; f < m.faceCount(); ++f) {
    const uint32_t* v = &m.faceVertices[3 * f];
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) return "face " + std::to_string(f) + " repeats a vertex";
    const Vec3 n = cross(sub(m.positions[v[1]], m.positions[v[0]]), sub(m.positions[v[2]], m.positions[v[0]]));
    if (n.x == 0 && n.y == 0 && n.z == 0) return "face " + std::to_string(f) + " has zero area";
    for (int e = 0; e < 3; ++e) {
      if (++directed[{v[e], v[(e + 1) % 3]}] > 1) return "directed edge used twice (orientation or non-manifold)";
      around[v[e]].push_back({v[(e + 1) % 3], v[(e + 2) % 3]});
    }
  }
  for (const auto& [e, count] : directed)
    if (!directed.count({e.second, e.first})) return "boundary edge " + std::to_string(e.first);
  for (size_t v = 0; v < around.size(); ++v) {
    if (around[v].empty()) return "unused vertex " + std::to_string(v);
    // One fan: following face to face (next of one = previous of another) visits every face around v.
    std::map<uint32_t, uint32_t> step;
    for (const auto& [next, prev] : around[v]) step[prev] = next;
    uint32_t at = around[v][0].first;
    size_t visited = 0;
    do {
      at = step.at(at);
      ++visited;
    } while (at != around[v][0].first && visited <= around[v].size());
    if (visited != around[v].size()) return "vertex " + std::to_string(v) + " has several fans";
  }
  std::set<std::tuple<double, double, double>> distinct;
  for (const Vec3& p : m.positions)
    if (!distinct.insert({p.x, p.y, p.z}).second) return "duplicate vertex";
  return "";
}

double signedVolume(const VoxelMesh& m) {
  double v = 0;
  for (size_t f = 0; f < m.faceCount(); ++f) {
    const Vec3 &a = m.positions[m.faceVertices[3 * f]], &b = m.positions[m.faceVertices[3 * f + 1]],
               &c = m.positions[m.faceVertices[3 * f + 2]];
    const Vec3 n = cross(b, c);
    v += (a.x * n.x + a.y * n.y + a.z * n.z) / 6;
  }
  return v;
}

double cellDiagonal(const Grid& g) {
  double d = 0;
  for (int a = 0; a < 3; ++a) d += std::pow((g.bounds.hi[a] - g.bounds.lo[a]) / g.dims[a], 2);
  return std::sqrt(d);
}

bool onBounds(const Grid& g, const Vec3& p) {
  for (int a = 0; a < 3; ++a) {
    const double tol = 1e-9 * (g.bounds.hi[a] - g.bounds.lo[a]);
    if (std::fabs(p[a] - g.bounds.lo[a]) <= tol || std::fabs(p[a] - g.bounds.hi[a]) <= tol) return true;
  }
  return false;
}

// The largest |d(vertex) - level| over the vertices not on the closing cap, by the exact point distances.
double largestVertexError(const Scene& s, const Grid& g, const VoxelMesh& m, double level) {
  std::vector<double> points;
  for (const Vec3& p : m.positions)
    if (!onBounds(g, p)) points.insert(points.end(), {p.x, p.y, p.z});
  const size_t n = points.size() / 3;
  std::vector<double> d(n), closest(3 * n);
  std::vector<int64_t> prim(n);
  pointDistances(s, points, true, {d, prim, closest});
  double worst = 0;
  for (double x : d) worst = std::max(worst, std::fabs(x - level));
  return worst;
}

Grid bandGrid(const Scene& s, VoxelizeOptions o, double half = 3) {
  Grid g = voxelizeScene(s, o);
  SdfOptions so;
  so.halfWidth = half;
  storeSignedDistances(g, s, so, false);
  return g;
}

// Closed, manifold, oriented; for a closed mesh (a continuous signed distance) every vertex off the cap within a
// cell diagonal of the level (the stated bound). An open mesh's sign jumps where its winding number crosses 1/2
// (the caps of its holes), and the vertices there lie on that jump instead.
VoxelMesh checkedSurface(const Scene& s, const Grid& g, double level = 0, bool closed = true) {
  const VoxelMesh m = extractLevelSurface(g, level);
  EXPECT_EQ(topologyDefect(m), "");
  if (m.faceCount() > 0) {
    EXPECT_GT(signedVolume(m), 0);
  }
  if (closed) {
    EXPECT_LE(largestVertexError(s, g, m, level), cellDiagonal(g) * (1 + 1e-9));
  }
  return m;
}

void addBox(Scene& s, const Vec3& lo, const Vec3& hi, bool insideOut = false) {
  static constexpr int kFaces[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                        {2, 3, 7}, {2, 7, 6}, {1, 2, 6}, {1, 6, 5}, {0, 4, 7}, {0, 7, 3}};
  const Vec3 v[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                     {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  for (const auto& f : kFaces) {
    Triangle t;
    t.v = {v[f[0]], v[insideOut ? f[2] : f[1]], v[insideOut ? f[1] : f[2]]};
    s.triangles.push_back(t);
  }
}

VoxelizeOptions resolution(uint32_t r, std::optional<Box> bounds = std::nullopt) {
  VoxelizeOptions o;
  o.resolution = r;
  o.bounds = bounds;
  return o;
}

TEST(LevelSurface, BoxVolumeAndOffsets) {
  Scene s;
  addBox(s, {0, 0, 0}, {1, 2, 3});
  // Bounds with half a unit to spare, so that grown surfaces stay inside the grid (no cap); cells of 1/8.
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{16, 24, 32};
  o.bounds = Box{{-0.5, -0.5, -0.5}, {1.5, 2.5, 3.5}};
  const Grid g = bandGrid(s, o);
  const double h = 0.125;
  // The interpolant's level set cuts the box's edges and corners: within a cell's width of the surface area.
  const double area = 2 * (2 + 3 + 6);
  EXPECT_NEAR(signedVolume(checkedSurface(s, g)), 6, area * h);
  for (double level : {-h, -0.5 * h, 0.3 * h, h}) {
    const VoxelMesh m = checkedSurface(s, g, level);
    // The offset solid of a box: volume + area * level (+ edges and corners rounded, of order level^2).
    EXPECT_NEAR(signedVolume(m), 6 + area * level, area * h) << level;
  }
}

TEST(LevelSurface, RefusesWithoutDistancesAndBeyondTheBand) {
  Scene s;
  addBox(s, {0, 0, 0}, {1, 1, 1});
  Grid g = voxelizeScene(s, resolution(8));
  try {
    extractLevelSurface(g, 0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--sdf"), std::string::npos);
  }
  g = bandGrid(s, resolution(8));
  const double largest = largestSurfaceLevel(g);
  EXPECT_NEAR(largest, (3 - std::sqrt(3.0)) / 8, 1e-12);
  EXPECT_NO_THROW(extractLevelSurface(g, largest));
  EXPECT_NO_THROW(extractLevelSurface(g, -largest));
  EXPECT_THROW(extractLevelSurface(g, std::nextafter(largest, 1.0)), InputError);
  EXPECT_THROW(extractLevelSurface(g, NAN), InputError);
  EXPECT_THROW(extractLevelSurface(bandGrid(s, resolution(8), 1.5), 0), InputError);  // narrower than a diagonal
}

TEST(LevelSurface, CourseMeshes) {
  for (const char* name : {"cube.obj", "diamond.obj", "bunny_200.obj", "bunny_1k.obj", "bunny_5k.obj", "bunny_40k.obj",
                           "vase.obj", "6.837.obj"}) {
    SCOPED_TRACE(name);
    const Scene s = loadScene(seed(std::string("6837/scenes/") + name));
    VoxelizeOptions o = withCubicCells(s, resolution(kSanitized ? 16 : 40));
    const std::string n = name;
    checkedSurface(s, bandGrid(s, o), 0, n != "vase.obj" && n != "6.837.obj");
  }
}

TEST(LevelSurface, OpenBunny) {
  const Scene s = loadScene(seed("meshes/bun_zipper.ply"));
  const Grid g = bandGrid(s, withCubicCells(s, resolution(kSanitized ? 24 : 64)));
  checkedSurface(s, g, 0, false);
}

// Layers of cubes are marched in parallel and the vertices numbered plane by plane: one thread and four give the
// same mesh, bit for bit (vertices in edge order, faces in cube order), on an open mesh and at a level != 0.
TEST(LevelSurface, SameMeshOnOneThreadAndOnFour) {
  const Scene open = loadScene(seed("meshes/bun_zipper.ply"));
  const Scene closed = loadScene(seed("6837/scenes/bunny_5k.obj"));
  const Grid a = bandGrid(open, withCubicCells(open, resolution(kSanitized ? 20 : 48)));
  const Grid b = bandGrid(closed, withCubicCells(closed, resolution(kSanitized ? 20 : 40)), 4);
  for (const auto& [grid, level] :
       {std::pair<const Grid*, double>{&a, 0.0}, {&b, -0.3 * (b.bounds.hi.x - b.bounds.lo.x) / b.dims[0]}}) {
    VoxelMesh one, four;
    tbb::task_arena(1).execute([&] { one = extractLevelSurface(*grid, level); });
    tbb::task_arena(4).execute([&] { four = extractLevelSurface(*grid, level); });
    ASSERT_GT(one.faceCount(), 0u);
    EXPECT_EQ(one.faceVertices, four.faceVertices);
    EXPECT_EQ(one.faceStart, four.faceStart);
    ASSERT_EQ(one.positions.size(), four.positions.size());
    for (size_t v = 0; v < one.positions.size(); ++v)
      for (int axis = 0; axis < 3; ++axis) ASSERT_EQ(one.positions[v][axis], four.positions[v][axis]) << v;
  }
}

TEST(LevelSurface, FractionsVolumeOfClosedMeshes) {
  for (const char* name : {"bunny_5k.obj", "diamond.obj"}) {
    SCOPED_TRACE(name);
    const Scene s = loadScene(seed(std::string("6837/scenes/") + name));
    Grid g = voxelizeScene(s, withCubicCells(s, resolution(48)));
    fillSolid(g, s, fillForFractions({}));
    double exact = double(g.solidCount());
    for (double f : volumeFractions(g, s)) exact += f;
    const double h = (g.bounds.hi.x - g.bounds.lo.x) / g.dims[0], cell = h * h * h;
    exact *= cell;
    SdfOptions so;
    storeSignedDistances(g, s, so, true);
    const VoxelMesh m = checkedSurface(s, g);
    // The surface area (from the mesh) times a tenth of a cell: the stated bound (docs/vox-export.md).
    double area = 0;
    for (size_t f = 0; f < m.faceCount(); ++f) {
      const Vec3 n = cross(sub(m.positions[m.faceVertices[3 * f + 1]], m.positions[m.faceVertices[3 * f]]),
                           sub(m.positions[m.faceVertices[3 * f + 2]], m.positions[m.faceVertices[3 * f]]));
      area += 0.5 * std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    }
    EXPECT_NEAR(signedVolume(m), exact, 0.1 * h * area);
  }
}

TEST(LevelSurface, SoupBoxesUlpApartSlabAndFlippedNormals) {
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> u(-1, 1);
  Scene soup;
  for (int t = 0; t < 100; ++t) {
    Triangle tri;
    tri.v = {Vec3{u(rng), u(rng), u(rng)}, Vec3{u(rng), u(rng), u(rng)}, Vec3{u(rng), u(rng), u(rng)}};
    soup.triangles.push_back(tri);
  }
  checkedSurface(soup, bandGrid(soup, withCubicCells(soup, resolution(32))), 0, false);

  Scene twoBoxes;
  addBox(twoBoxes, {0, 0, 0}, {1, 1, 1});
  addBox(twoBoxes, {std::nextafter(1.0, 2.0), 0, 0}, {2, 1, 1});
  checkedSurface(twoBoxes, bandGrid(twoBoxes, withCubicCells(twoBoxes, resolution(16))));

  Scene slab;  // 0.005 thick, cells of 0.075: no centre inside at level 0, a shell around it at 0.04
  addBox(slab, {0, 0, 0}, {1, 1, 0.005});
  VoxelizeOptions so;
  so.dims = std::array<uint32_t, 3>{20, 20, 6};
  so.bounds = Box{{-0.25, -0.25, -0.225}, {1.25, 1.25, 0.225}};
  const Grid slabGrid = bandGrid(slab, so);
  EXPECT_EQ(checkedSurface(slab, slabGrid).faceCount(), 0u);
  EXPECT_GT(signedVolume(checkedSurface(slab, slabGrid, 0.04)), 0.08 * 1.0 * 0.5);

  Scene flipped = loadScene(seed("6837/scenes/bunny_1k.obj"));
  for (size_t t = 0; t < flipped.triangles.size(); ++t)
    if (rng() & 1) std::swap(flipped.triangles[t].v[1], flipped.triangles[t].v[2]);
  checkedSurface(flipped, bandGrid(flipped, withCubicCells(flipped, resolution(32))), 0, false);
}

TEST(LevelSurface, OneCellAndBoundsCuttingTheSurface) {
  Scene s;
  addBox(s, {0, 0, 0}, {1, 1, 1});
  // One cell inside the box: its centre is inside, the cap closes it to an octahedron-like cell of 8 faces' fans.
  Grid one = bandGrid(
      s,
      [] {
        VoxelizeOptions o;
        o.dims = std::array<uint32_t, 3>{1, 1, 1};
        o.bounds = Box{{0.4, 0.4, 0.4}, {0.6, 0.6, 0.6}};
        return o;
      }(),
      64);
  const VoxelMesh m = extractLevelSurface(one, 0);
  EXPECT_EQ(topologyDefect(m), "");
  EXPECT_GT(signedVolume(m), 0);
  // Bounds cutting the box through its middle: closed by a cap on the bounds.
  VoxelizeOptions cut;
  cut.dims = std::array<uint32_t, 3>{20, 20, 20};
  cut.bounds = Box{{-0.25, -0.25, -0.25}, {0.5, 0.5, 0.5}};
  const Grid g = bandGrid(s, cut);
  LevelSurfaceStats stats;
  const VoxelMesh c = extractLevelSurface(g, 0, &stats);
  EXPECT_EQ(topologyDefect(c), "");
  EXPECT_GT(stats.capTriangles, 0u);
  // The part of the unit cube inside the bounds: 0.5^3, up to the interpolation along the three faces.
  EXPECT_NEAR(signedVolume(c), 0.125, 3 * 0.25 * (0.75 / 20));
  // Bounds entirely inside the box: the band is empty, so the grid is taken as outside (documented).
  VoxelizeOptions inner;
  inner.dims = std::array<uint32_t, 3>{4, 4, 4};
  inner.bounds = Box{{0.45, 0.45, 0.45}, {0.55, 0.55, 0.55}};
  EXPECT_EQ(extractLevelSurface(bandGrid(s, inner), 0).faceCount(), 0u);
}

TEST(LevelSurface, ClosedEvenWhereTheBandHasAHole) {
  // A band that breaks the 1-Lipschitz rule (a cell next to the surface dropped, as an open mesh's sign jump does):
  // the cells outside the band take their row's nearest band cell's side, and every cube whose sides differ is
  // marched, so the surface stays closed.
  Scene s;
  addBox(s, {0, 0, 0}, {1, 1, 1});
  Grid g = bandGrid(s, resolution(8));
  size_t dropped = 0;
  for (size_t b = 0; b < g.sdfKeys.size() && dropped < 5; ++b)
    if (std::fabs(g.sdfValues[b]) < 0.1 && b % 7 == 0) {
      g.sdfKeys.erase(g.sdfKeys.begin() + ptrdiff_t(b));
      g.sdfValues.erase(g.sdfValues.begin() + ptrdiff_t(b));
      ++dropped;
    }
  EXPECT_EQ(dropped, 5u);
  EXPECT_EQ(topologyDefect(extractLevelSurface(g, 0)), "");
}

// Random closed boxes (some inside out), overlapping boxes, open boxes and triangle soups; random grids, bounds
// and levels within the band.
RC_GTEST_PROP(LevelSurfaceProperties, ClosedManifoldOrientedAndNearTheLevel, ()) {
  Scene s;
  const int kind = *rc::gen::inRange(0, 4);
  const auto coord = [] { return *rc::gen::inRange(-16, 25) / 8.0; };
  const auto size = [] { return *rc::gen::inRange(1, 17) / 8.0; };
  if (kind <= 2) {
    const Vec3 lo{coord(), coord(), coord()};
    addBox(s, lo, Vec3{lo.x + size(), lo.y + size(), lo.z + size()}, kind == 1);
    if (kind == 2) s.triangles.resize(12 - size_t(*rc::gen::inRange(1, 6)));
  } else {
    const int n = *rc::gen::inRange(1, 12);
    for (int t = 0; t < n; ++t) {
      Triangle tri;
      tri.v = {Vec3{coord(), coord(), coord()}, Vec3{coord(), coord(), coord()}, Vec3{coord(), coord(), coord()}};
      s.triangles.push_back(tri);
    }
  }
  VoxelizeOptions o;
  const uint32_t r = uint32_t(*rc::gen::inRange(1, 17));
  o.dims = std::array<uint32_t, 3>{r, r, r};
  const Box b = *sceneBounds(s);
  const double cutBy = *rc::gen::element(-0.25, 0.0, 0.25);  // bounds cutting the scene, exact, or around it
  const double side = std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z, 0.25});
  o.bounds = Box{b.lo - Vec3{1, 1, 1} * (-cutBy * side), b.lo + Vec3{1, 1, 1} * (side * (1 + cutBy))};
  const double half = *rc::gen::element(2.0, 3.0, 5.0);
  Grid g;
  try {
    g = bandGrid(s, o, half);
  } catch (const Error&) {
    RC_DISCARD("refused");
  }
  const double largest = largestSurfaceLevel(g);
  const double level = largest * *rc::gen::inRange(-8, 9) / 8.0;
  const VoxelMesh m = extractLevelSurface(g, level);
  RC_ASSERT(topologyDefect(m) == "");
  if (m.faceCount() > 0) RC_ASSERT(signedVolume(m) > 0);
  if (kind <= 1) RC_ASSERT(largestVertexError(s, g, m, level) <= cellDiagonal(g) * (1 + 1e-9));
}

}  // namespace
}  // namespace vox
