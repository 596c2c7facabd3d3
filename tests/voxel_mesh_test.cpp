// Tests of buildVoxelMesh and triangulateVoxelMesh on hand-made grids: counts, closedness, 2-manifoldness,
// orientation, enclosed volume, area, Euler characteristic against the voxel set's topology, and no T-junctions.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "vox/core/colormap.h"
#include "vox/core/error.h"
#include "vox/export/voxel_mesh.h"

namespace vox {
namespace {

using IntCell = std::array<int, 3>;
using IntCellSet = std::set<IntCell>;

// A grid whose cells are `cells`; cell c holds 1 + (its rank % 3) primitives (triangles of the scene below).
// The bounds give non-uniform but binary-exact cell sizes (0.5, 0.25, 2), so volumes and areas are exact sums.
Grid makeGrid(const std::array<uint32_t, 3>& dims, const IntCellSet& cells, const IntCellSet& solid = {}) {
  Grid g;
  g.dims = dims;
  g.bounds = {{-1, 2, 0.5}, {-1 + 0.5 * dims[0], 2 + 0.25 * dims[1], 0.5 + 2.0 * dims[2]}};
  std::vector<uint64_t> keys;
  for (const IntCell& c : cells) keys.push_back(cellKey(dims, c[0], c[1], c[2]));
  std::sort(keys.begin(), keys.end());
  g.cellKeys.assign(keys.begin(), keys.end());
  g.cellStart = {0};
  for (size_t i = 0; i < keys.size(); ++i) {
    for (uint32_t p = 0; p <= i % 3; ++p) g.primIds.push_back(p);
    g.cellStart.push_back(g.primIds.size());
  }
  std::vector<uint64_t> solidKeys;
  for (const IntCell& c : solid) solidKeys.push_back(cellKey(dims, c[0], c[1], c[2]));
  std::sort(solidKeys.begin(), solidKeys.end());
  for (uint64_t key : solidKeys) appendSolidKey(g.solidRuns, key);
  return g;
}

Scene makeScene() {
  Scene s;
  for (int m = 0; m < 3; ++m) {
    Material mat;
    mat.diffuse = {m == 0 ? 1.0 : 0.0, m == 1 ? 1.0 : 0.0, m == 2 ? 1.0 : 0.0};
    s.materials.push_back(mat);
    Triangle t;
    t.v = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};
    t.material = uint32_t(m);
    s.triangles.push_back(t);
  }
  return s;
}

double cellVolume(const Grid& g) {
  double v = 1;
  for (int a = 0; a < 3; ++a) v *= (g.bounds.hi[a] - g.bounds.lo[a]) / g.dims[a];
  return v;
}

uint64_t edgeKey(uint32_t a, uint32_t b) { return (uint64_t(a) << 32) | b; }

// Everything we check about a closed polygon mesh, computed from the mesh alone.
struct Topology {
  bool closed = true;          // every directed edge once, and its reverse once
  bool vertexManifold = true;  // the faces around every vertex form one cycle
  bool noUnusedVertex = true;
  size_t edges = 0;
  long euler = 0;
  size_t components = 0;  // connected components of faces
  double volume = 0, area = 0;
};

Topology analyse(const VoxelMesh& m, const Vec3& ref) {
  Topology t;
  std::unordered_map<uint64_t, uint32_t> directed;  // directed edge -> face
  std::vector<uint32_t> used(m.vertexCount(), 0);
  for (size_t f = 0; f < m.faceCount(); ++f) {
    const uint32_t b = m.faceStart[f], e = m.faceStart[f + 1];
    for (uint32_t k = b; k < e; ++k) {
      const uint32_t u = m.faceVertices[k], v = m.faceVertices[k + 1 < e ? k + 1 : b];
      if (!directed.emplace(edgeKey(u, v), uint32_t(f)).second) t.closed = false;
      ++used[u];
    }
    // Signed volume (divergence theorem) and area by a fan from the first vertex; exact for planar convex faces.
    const Vec3 p0 = m.positions[m.faceVertices[b]] - ref;
    Vec3 n;
    for (uint32_t k = b + 1; k + 1 < e; ++k) {
      const Vec3 p1 = m.positions[m.faceVertices[k]] - ref, p2 = m.positions[m.faceVertices[k + 1]] - ref;
      t.volume += dot(p0, cross(p1, p2)) / 6;
      n = n + cross(p1 - p0, p2 - p0);
    }
    t.area += length(n) / 2;
  }
  for (const auto& [key, f] : directed)
    if (!directed.count((key << 32) | (key >> 32))) t.closed = false;
  t.edges = directed.size() / 2;
  for (uint32_t u : used)
    if (!u) t.noUnusedVertex = false;
  t.euler = long(m.vertexCount()) - long(t.edges) + long(m.faceCount());

  // Around vertex v, corner (u -> v -> w) is followed by the corner of the face across edge (v, w), which enters v
  // from w. One cycle per vertex means a single fan.
  std::unordered_map<uint64_t, uint32_t> cornerNext;  // (v, u) -> w
  for (size_t f = 0; f < m.faceCount(); ++f) {
    const uint32_t b = m.faceStart[f], e = m.faceStart[f + 1], n = e - b;
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t u = m.faceVertices[b + (k + n - 1) % n], v = m.faceVertices[b + k],
                     w = m.faceVertices[b + (k + 1) % n];
      cornerNext[edgeKey(v, u)] = w;
    }
  }
  std::vector<uint32_t> seen(m.vertexCount(), 0);
  for (const auto& [key, w0] : cornerNext) {
    const uint32_t v = uint32_t(key >> 32);
    if (seen[v]) continue;
    uint32_t in = uint32_t(key), steps = 0;
    do {
      auto it = cornerNext.find(edgeKey(v, in));
      if (it == cornerNext.end()) break;
      in = it->second;
      ++steps;
    } while (in != uint32_t(key) && steps <= used[v]);
    seen[v] = 1;
    if (steps != used[v]) t.vertexManifold = false;
  }

  // Face components through shared edges.
  std::vector<uint32_t> parent(m.faceCount());
  std::iota(parent.begin(), parent.end(), 0);
  std::function<uint32_t(uint32_t)> find = [&](uint32_t x) { return parent[x] == x ? x : parent[x] = find(parent[x]); };
  for (const auto& [key, f] : directed) {
    auto it = directed.find((key << 32) | (key >> 32));
    if (it != directed.end()) parent[find(f)] = find(it->second);
  }
  for (uint32_t f = 0; f < m.faceCount(); ++f) t.components += find(f) == f;
  return t;
}

// ----- independent topology of a voxel set -----

// Cubical Euler characteristic of the union of closed cubes: chi = V - E + F - C over the cells of the complex.
long cubicalEuler(const IntCellSet& cells) {
  std::set<std::array<int, 4>> verts, edges, faces;  // (x2, y2, z2) doubled coordinates of centres
  for (const IntCell& c : cells)
    for (int dz = 0; dz <= 2; ++dz)
      for (int dy = 0; dy <= 2; ++dy)
        for (int dx = 0; dx <= 2; ++dx) {
          const int odd = (dx == 1) + (dy == 1) + (dz == 1);
          const std::array<int, 4> p{2 * c[0] + dx, 2 * c[1] + dy, 2 * c[2] + dz, 0};
          if (odd == 0) verts.insert(p);
          if (odd == 1) edges.insert(p);
          if (odd == 2) faces.insert(p);
        }
  return long(verts.size()) - long(edges.size()) + long(faces.size()) - long(cells.size());
}

// Components of a set of cells under face adjacency.
size_t faceComponents(const IntCellSet& cells) {
  std::set<IntCell> left = cells;
  size_t n = 0;
  while (!left.empty()) {
    ++n;
    std::vector<IntCell> stack{*left.begin()};
    left.erase(left.begin());
    while (!stack.empty()) {
      const IntCell c = stack.back();
      stack.pop_back();
      for (int a = 0; a < 3; ++a)
        for (int s : {-1, 1}) {
          IntCell d = c;
          d[a] += s;
          auto it = left.find(d);
          if (it != left.end()) {
            stack.push_back(d);
            left.erase(it);
          }
        }
    }
  }
  return n;
}

// Empty components enclosed by the voxels (cavities), in the box grown by one cell so the outside is one component.
size_t cavities(const IntCellSet& cells, const std::array<uint32_t, 3>& dims) {
  IntCellSet empty;
  for (int z = -1; z <= int(dims[2]); ++z)
    for (int y = -1; y <= int(dims[1]); ++y)
      for (int x = -1; x <= int(dims[0]); ++x)
        if (!cells.count({x, y, z})) empty.insert({x, y, z});
  return faceComponents(empty) - 1;
}

// Well-composed sets (no two cells meeting only along an edge or at a corner, neither voxels nor empty cells):
// add voxels until no critical configuration is left. For them the closed union is a 3-manifold with boundary and
// the voxel surface's Euler characteristic is twice the union's.
IntCellSet makeWellComposed(IntCellSet cells, const std::array<uint32_t, 3>& dims) {
  auto in = [&](int x, int y, int z) { return cells.count({x, y, z}) > 0; };
  for (bool changed = true; changed;) {
    changed = false;
    for (int z = -1; z < int(dims[2]); ++z)
      for (int y = -1; y < int(dims[1]); ++y)
        for (int x = -1; x < int(dims[0]); ++x) {
          // 2x2x2 block with corner (x,y,z); any cell outside the grid is empty.
          int occ = 0;
          for (int o = 0; o < 8; ++o) occ |= int(in(x + (o & 1), y + ((o >> 1) & 1), z + (o >> 2))) << o;
          auto fillOne = [&](int o) {
            const IntCell c{x + (o & 1), y + ((o >> 1) & 1), z + (o >> 2)};
            if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= int(dims[0]) || c[1] >= int(dims[1]) ||
                c[2] >= int(dims[2]))
              return false;
            cells.insert(c);
            return true;
          };
          auto critical = [&]() {
            // 2x2 squares in the block's six faces: diagonal equal, anti-diagonal equal, the two different.
            for (int a = 0; a < 3; ++a)
              for (int s = 0; s < 2; ++s) {
                const int b = (a + 1) % 3, c = (a + 2) % 3;
                auto bit = [&](int bb, int bc) { return (occ >> ((s << a) | (bb << b) | (bc << c))) & 1; };
                if (bit(0, 0) == bit(1, 1) && bit(1, 0) == bit(0, 1) && bit(0, 0) != bit(1, 0)) return true;
              }
            for (int o = 0; o < 4; ++o) {
              const int anti = 7 - o, pair = (1 << o) | (1 << anti);
              if (occ == pair || occ == (255 ^ pair)) return true;
            }
            return false;
          };
          if (!critical()) continue;
          for (int o = 0; o < 8; ++o)
            if (!((occ >> o) & 1) && fillOne(o)) {
              changed = true;
              break;
            }
        }
  }
  return cells;
}

IntCellSet randomCells(std::mt19937& rng, const std::array<uint32_t, 3>& dims, double density) {
  std::bernoulli_distribution take(density);
  IntCellSet cells;
  for (uint32_t z = 0; z < dims[2]; ++z)
    for (uint32_t y = 0; y < dims[1]; ++y)
      for (uint32_t x = 0; x < dims[0]; ++x)
        if (take(rng)) cells.insert({int(x), int(y), int(z)});
  return cells;
}

// Faces every client triangulates right (issue 10): triangles of non-zero area and quads with no three vertices
// on a line. Returns the number of triangles.
size_t expectClientSafeFaces(const VoxelMesh& m) {
  size_t triangles = 0, bad = 0;
  for (size_t f = 0; f < m.faceCount() && bad < 5; ++f) {
    const size_t n = m.faceSize(f);
    if (n != 3 && n != 4) {
      ADD_FAILURE() << "face " << f << " has " << n << " vertices";
      ++bad;
      continue;
    }
    triangles += n == 3;
    for (size_t k = 0; k < n; ++k) {
      auto corner = [&](size_t j) { return m.positions[m.faceVertices[m.faceStart[f] + j % n]]; };
      const Vec3 a = corner(k), b = corner(k + 1), c = corner(k + 2);
      if (length(cross(b - a, c - b)) == 0) {
        ADD_FAILURE() << "face " << f << " (" << n << " vertices) has three vertices on a line";
        ++bad;
        break;
      }
    }
  }
  return triangles;
}

// Triangles a client makes of the mesh (a polygon of n vertices gives n - 2).
size_t triangleCount(const VoxelMesh& m) { return m.faceVertices.size() - 2 * m.faceCount(); }

void expectSound(const VoxelMesh& mesh, const Grid& grid, size_t voxels, const std::string& what) {
  SCOPED_TRACE(what);
  expectClientSafeFaces(mesh);
  const Topology t = analyse(mesh, grid.bounds.lo);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.vertexManifold);
  EXPECT_TRUE(t.noUnusedVertex);
  EXPECT_NEAR(t.volume, double(voxels) * cellVolume(grid), 1e-9 * std::max(1.0, t.volume));
  EXPECT_EQ(t.euler % 2, 0);
  EXPECT_LE(t.euler, 2 * long(t.components));
}

// ----- tests -----

TEST(ColorMap, EndsAndMonotoneLuminance) {
  const Vec3 lo = countColor(1, 100), hi = countColor(100, 100);
  EXPECT_NEAR(lo.x, 68 / 255.0, 1e-12);
  EXPECT_NEAR(hi.z, 37 / 255.0, 1e-12);
  auto luma = [](const Vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
  for (uint32_t n = 1; n < 100; ++n) EXPECT_LT(luma(countColor(n, 100)), luma(countColor(n + 1, 100))) << n;
  const Vec3 zero = countColor(0, 0);
  EXPECT_EQ(zero.x, lo.x);
}

TEST(VoxelMesh, AllModeHasACubePerVoxel) {
  std::mt19937 rng(1);
  const std::array<uint32_t, 3> dims{5, 4, 3};
  const IntCellSet cells = randomCells(rng, dims, 0.4);
  const IntCellSet solid{{4, 3, 2}};
  const Grid g = makeGrid(dims, cells, solid);
  const size_t n = cells.size() + (cells.count({4, 3, 2}) ? 0 : 1);
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::All, ColorMode::Count);
  ASSERT_EQ(m.vertexCount(), 8 * n);
  ASSERT_EQ(m.faceCount(), 12 * n);
  EXPECT_TRUE(m.isTriangleMesh());
  ASSERT_EQ(m.faceColors.size(), m.faceCount());
  // Each cube is a closed, outward-oriented surface of the cell's volume.
  const Topology t = analyse(m, g.bounds.lo);
  EXPECT_TRUE(t.closed);
  EXPECT_EQ(t.components, n);
  EXPECT_NEAR(t.volume, double(n) * cellVolume(g), 1e-9);
  EXPECT_EQ(t.euler, 2 * long(n));
}

struct KnownShape {
  const char* name;
  std::array<uint32_t, 3> dims;
  IntCellSet cells;
  long euler;       // of the voxel surface, from the shape's construction
  size_t vertices;  // of the exposed mesh, 0 when not checked
};

std::vector<KnownShape> knownShapes() {
  std::vector<KnownShape> s;
  s.push_back({"cube", {1, 1, 1}, {{0, 0, 0}}, 2, 8});
  s.push_back({"edge pair", {2, 2, 1}, {{0, 0, 0}, {1, 1, 0}}, 4, 16});  // two spheres, edge split at both ends
  s.push_back({"corner pair", {2, 2, 2}, {{0, 0, 0}, {1, 1, 1}}, 4, 16});
  s.push_back({"checkerboard 2x2x2", {2, 2, 2}, {{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}}, 8, 32});
  IntCellSet ring;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      if (x != 1 || y != 1) ring.insert({x, y, 0});
  s.push_back({"torus ring", {3, 3, 1}, ring, 0, 32});
  IntCellSet twoHoles;
  for (int x = 0; x < 5; ++x)
    for (int y = 0; y < 3; ++y)
      if (y != 1 || (x != 1 && x != 3)) twoHoles.insert({x, y, 0});
  s.push_back({"double torus", {5, 3, 1}, twoHoles, -2, 0});
  IntCellSet hollow;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 3; ++z)
        if (x != 1 || y != 1 || z != 1) hollow.insert({x, y, z});
  s.push_back({"cavity", {3, 3, 3}, hollow, 4, 64});
  // 2x2x2 block without two opposite corners: a ball, but the centre point has two sheets (one per missing cell).
  IntCellSet block;
  for (int o = 1; o < 7; ++o) block.insert({o & 1, (o >> 1) & 1, o >> 2});
  s.push_back({"block minus opposite corners", {2, 2, 2}, block, 2, 0});
  // Full layer, diagonal pair, full layer: keeping the pair apart would collapse a tunnel onto the middle edge
  // (four faces on one edge); joining it leaves two dents in a ball.
  IntCellSet sandwich{{0, 0, 1}, {1, 1, 1}};
  for (int z : {0, 2})
    for (int o = 0; o < 4; ++o) sandwich.insert({o & 1, o >> 1, z});
  s.push_back({"sandwich", {2, 2, 3}, sandwich, 2, 0});
  // Edge-touching rings linked like a chain: two tori meeting along an edge stay two tori.
  IntCellSet chain = ring;
  for (int x = 0; x < 3; ++x)
    for (int z = 0; z < 3; ++z)
      if (x != 1 || z != 1) chain.insert({x + 3, 1, z + 1});
  s.push_back({"two rings at an edge", {6, 3, 4}, chain, 0, 0});
  return s;
}

TEST(VoxelMesh, KnownShapesExposedAndMerged) {
  for (const KnownShape& shape : knownShapes()) {
    SCOPED_TRACE(shape.name);
    const Grid g = makeGrid(shape.dims, shape.cells);
    const VoxelMesh exposed = buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::None);
    const VoxelMesh merged = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::None);
    for (const VoxelMesh* m : {&exposed, &merged}) {
      const Topology t = analyse(*m, g.bounds.lo);
      EXPECT_TRUE(t.closed);
      EXPECT_TRUE(t.vertexManifold);
      EXPECT_TRUE(t.noUnusedVertex);
      EXPECT_EQ(t.euler, shape.euler);
      EXPECT_NEAR(t.volume, double(shape.cells.size()) * cellVolume(g), 1e-9);
    }
    if (shape.vertices) {
      EXPECT_EQ(exposed.vertexCount(), shape.vertices);
    }
    expectClientSafeFaces(exposed);
    expectClientSafeFaces(merged);
    EXPECT_LE(triangleCount(merged), triangleCount(exposed));
  }
}

TEST(VoxelMesh, ExposedFacesOfACube) {
  // A 2x3x4 box: exposed squares are its surface cells, merged faces are its six sides.
  IntCellSet box;
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 4; ++z) box.insert({x, y, z});
  const Grid g = makeGrid({4, 5, 6}, box);
  const VoxelMesh e = buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::None);
  EXPECT_EQ(e.faceCount(), size_t(2 * (2 * 3 + 3 * 4 + 2 * 4)));
  EXPECT_EQ(e.vertexCount(), size_t(3 * 4 * 5 - 1 * 2 * 3));
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::None);
  EXPECT_EQ(m.faceCount(), 6u);
  EXPECT_EQ(m.vertexCount(), 8u);
  // With count colours the cells differ, so fewer squares merge, but never more faces than squares.
  const VoxelMesh mc = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::Count);
  EXPECT_GT(mc.faceCount(), 6u);
  EXPECT_LE(mc.faceCount(), e.faceCount());
  expectSound(mc, g, box.size(), "coloured merge");
}

TEST(VoxelMesh, RandomSetsAreClosedManifoldsOfTheRightVolume) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const std::array<uint32_t, 3> dims{uint32_t(2 + trial % 7), uint32_t(2 + (trial / 2) % 6),
                                       uint32_t(1 + (trial / 3) % 6)};
    const double density = 0.15 + 0.7 * (trial % 10) / 10.0;
    const IntCellSet cells = randomCells(rng, dims, density);
    const Grid g = makeGrid(dims, cells);
    const std::string what = "trial " + std::to_string(trial);
    const VoxelMesh e = buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::Count);
    const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::None);
    const VoxelMesh mc = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::Material);
    expectSound(e, g, cells.size(), what + " exposed");
    expectSound(m, g, cells.size(), what + " merged");
    expectSound(mc, g, cells.size(), what + " merged by material");
    const Topology te = analyse(e, g.bounds.lo), tm = analyse(m, g.bounds.lo);
    EXPECT_LE(triangleCount(m), triangleCount(e)) << what;
    EXPECT_NEAR(tm.area, te.area, 1e-9 * std::max(1.0, te.area)) << what;
    EXPECT_NEAR(tm.volume, te.volume, 1e-9 * std::max(1.0, te.volume)) << what;
    EXPECT_EQ(tm.euler, te.euler) << what;
    EXPECT_EQ(tm.components, te.components) << what;
  }
}

TEST(VoxelMesh, LargeDenseRandomSetsStayManifold) {
  // Dense sets exercise every configuration around lattice points and edges, across brick boundaries.
  std::mt19937 rng(11);
  for (double density : {0.3, 0.5, 0.7}) {
    const std::array<uint32_t, 3> dims{19, 17, 18};
    const IntCellSet cells = randomCells(rng, dims, density);
    const Grid g = makeGrid(dims, cells);
    expectSound(buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::None), g, cells.size(), "exposed");
    expectSound(buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::None), g, cells.size(), "merged");
  }
}

TEST(VoxelMesh, EulerCharacteristicMatchesWellComposedSets) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 40; ++trial) {
    const std::array<uint32_t, 3> dims{uint32_t(3 + trial % 5), uint32_t(3 + (trial / 5) % 4), uint32_t(2 + trial % 4)};
    const IntCellSet cells = makeWellComposed(randomCells(rng, dims, 0.35 + 0.05 * (trial % 6)), dims);
    const Grid g = makeGrid(dims, cells);
    const std::string what = "trial " + std::to_string(trial);
    const long chi = 2 * cubicalEuler(cells);
    // components of the surface = voxel components + cavities; tunnels = components - chi / 2.
    const size_t surfaces = faceComponents(cells) + cavities(cells, dims);
    for (FaceMode mode : {FaceMode::Exposed, FaceMode::Merged}) {
      const Topology t = analyse(buildVoxelMesh(g, makeScene(), mode, ColorMode::None), g.bounds.lo);
      EXPECT_EQ(t.euler, chi) << what;
      EXPECT_EQ(t.components, surfaces) << what;
      EXPECT_TRUE(t.closed && t.vertexManifold) << what;
    }
  }
}

TEST(VoxelMesh, MergedHasNoTJunctions) {
  // Closedness (every directed edge matched by its reverse) already rules out T-junctions; check directly too:
  // no mesh vertex lies strictly inside a face's edge. Only on a well-composed set: where voxels meet along an
  // edge, the other sheet's vertices may lie on a face's edge without belonging to the same sheet.
  std::mt19937 rng(5);
  const std::array<uint32_t, 3> dims{11, 9, 5};
  const IntCellSet cells = makeWellComposed(randomCells(rng, dims, 0.45), dims);
  const Grid g = makeGrid(dims, cells);
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::Count);
  std::set<std::array<double, 3>> points;
  for (const Vec3& p : m.positions) points.insert({p.x, p.y, p.z});
  size_t checked = 0;
  for (size_t f = 0; f < m.faceCount(); ++f) {
    const uint32_t b = m.faceStart[f], e = m.faceStart[f + 1];
    for (uint32_t k = b; k < e; ++k) {
      const Vec3 p = m.positions[m.faceVertices[k]], q = m.positions[m.faceVertices[k + 1 < e ? k + 1 : b]];
      // Edges are axis-parallel sides or diagonals of triangulated rectangles; the grid's binary-exact cell sizes
      // make the collinearity test exact.
      for (const auto& r : points) {
        const Vec3 rp = Vec3{r[0], r[1], r[2]} - p, qp = q - p;
        if (length(cross(qp, rp)) == 0 && dot(rp, qp) > 0 && dot(rp, qp) < dot(qp, qp))
          ADD_FAILURE() << "vertex inside an edge of face " << f;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u);
  EXPECT_GT(expectClientSafeFaces(m), 0u) << "no rectangle needed triangles: the test lost its point";
}

TEST(VoxelMesh, TriangulationKeepsSurfaceWithoutDegenerateTriangles) {
  std::mt19937 rng(9);
  const std::array<uint32_t, 3> dims{8, 7, 6};
  const IntCellSet cells = randomCells(rng, dims, 0.5);
  const Grid g = makeGrid(dims, cells);
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::Count);
  const VoxelMesh t = triangulateVoxelMesh(m);
  ASSERT_TRUE(t.isTriangleMesh());
  EXPECT_EQ(t.faceVertices.size(), 3 * (m.faceVertices.size() - 2 * m.faceCount()));
  EXPECT_EQ(t.faceColors.size(), t.faceCount());
  for (size_t f = 0; f < t.faceCount(); ++f) {
    const Vec3 a = t.positions[t.faceVertices[3 * f]], b = t.positions[t.faceVertices[3 * f + 1]],
               c = t.positions[t.faceVertices[3 * f + 2]];
    ASSERT_GT(length(cross(b - a, c - a)), 0) << "degenerate triangle " << f;
  }
  const Topology tm = analyse(m, g.bounds.lo), tt = analyse(t, g.bounds.lo);
  EXPECT_TRUE(tt.closed);
  EXPECT_TRUE(tt.vertexManifold);
  EXPECT_EQ(tt.euler, tm.euler);
  EXPECT_NEAR(tt.volume, tm.volume, 1e-9);
  EXPECT_NEAR(tt.area, tm.area, 1e-9);
}

TEST(VoxelMesh, ColoursFollowCountsMaterialsAndSolidCells) {
  const IntCellSet cells{{0, 0, 0}, {2, 0, 0}, {4, 0, 0}};
  const IntCellSet solid{{0, 2, 0}};
  const Grid g = makeGrid({5, 3, 1}, cells, solid);  // cells hold 1, 2, 3 primitives (materials 0; 0,1; 0,1,2)
  const VoxelMesh count = buildVoxelMesh(g, makeScene(), FaceMode::All, ColorMode::Count);
  ASSERT_EQ(count.faceCount(), 48u);
  auto rgb = [](const Vec3& c) {
    return Rgb8{uint8_t(std::lround(c.x * 255)), uint8_t(std::lround(c.y * 255)), uint8_t(std::lround(c.z * 255))};
  };
  EXPECT_EQ(count.faceColors[0], rgb(countColor(1, 3)));
  EXPECT_EQ(count.faceColors[12], rgb(countColor(2, 3)));
  EXPECT_EQ(count.faceColors[24], rgb(countColor(3, 3)));
  EXPECT_EQ(count.faceColors[36], kSolidCellColor);
  const VoxelMesh mat = buildVoxelMesh(g, makeScene(), FaceMode::All, ColorMode::Material);
  // Ties go to the lowest material index: every cell holds material 0 once.
  EXPECT_EQ(mat.faceColors[0], (Rgb8{255, 0, 0}));
  EXPECT_EQ(mat.faceColors[24], (Rgb8{255, 0, 0}));
  EXPECT_TRUE(buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::None).faceColors.empty());
}

TEST(VoxelMesh, DominantVertexColoursCoverTheLargestAngle) {
  // A row of three voxels holding 1, 2 and 3 primitives: three count colours. Vertices on the row's ends see one
  // voxel only; those on a seam between two voxels see 180 degrees of each, and the tie goes to the smaller colour.
  const Grid g = makeGrid({3, 1, 1}, {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
  for (FaceMode mode : {FaceMode::Exposed, FaceMode::Merged}) {
    const VoxelMesh m = buildVoxelMesh(g, makeScene(), mode, ColorMode::Count);
    const std::vector<Rgb8> vc = dominantVertexColors(m);
    ASSERT_EQ(vc.size(), m.vertexCount());
    for (size_t v = 0; v < m.vertexCount(); ++v) {
      const int i = int(std::lround((m.positions[v].x - g.bounds.lo.x) / 0.5));  // lattice plane 0..3
      std::set<Rgb8> around;
      for (size_t f = 0; f < m.faceCount(); ++f)
        for (uint32_t k = m.faceStart[f]; k < m.faceStart[f + 1]; ++k)
          if (m.faceVertices[k] == v) around.insert(m.faceColors[f]);
      EXPECT_EQ(around.size(), i == 0 || i == 3 ? 1u : 2u) << "vertex " << v;
      // Ends: their one colour; seams: a tie of 180 degrees each, so the smaller colour.
      EXPECT_EQ(vc[v], *around.begin()) << "vertex " << v << " on lattice plane " << i;
    }
  }
  EXPECT_TRUE(dominantVertexColors(buildVoxelMesh(g, makeScene(), FaceMode::Exposed, ColorMode::None)).empty());
}

TEST(VoxelMesh, MaterialMajority) {
  Grid g = makeGrid({2, 1, 1}, {{0, 0, 0}});
  g.primIds = {1, 2, 2};
  g.cellStart = {0, 3};
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::All, ColorMode::Material);
  EXPECT_EQ(m.faceColors[0], (Rgb8{0, 0, 255}));
}

TEST(VoxelMesh, BadGridsThrow) {
  Grid g = makeGrid({2, 2, 2}, {{0, 0, 0}, {1, 1, 1}});
  Grid outside = g;
  outside.cellKeys.back() = 8;
  EXPECT_THROW(buildVoxelMesh(outside, makeScene(), FaceMode::Exposed, ColorMode::None), InputError);
  Grid unsorted = g;
  std::swap(unsorted.cellKeys[0], unsorted.cellKeys[1]);
  EXPECT_THROW(buildVoxelMesh(unsorted, makeScene(), FaceMode::Exposed, ColorMode::None), InputError);
  Grid badPrim = g;
  badPrim.primIds[0] = 99;
  EXPECT_THROW(buildVoxelMesh(badPrim, makeScene(), FaceMode::All, ColorMode::Material), InputError);
  EXPECT_THROW(parseFaceMode("some"), InputError);
  EXPECT_THROW(parseColorMode("rainbow"), InputError);
  EXPECT_EQ(parseFaceMode("merged"), FaceMode::Merged);
  EXPECT_EQ(parseColorMode("material"), ColorMode::Material);
}

TEST(VoxelMesh, EmptyGridGivesEmptyMesh) {
  const Grid g = makeGrid({3, 3, 3}, {});
  for (FaceMode mode : {FaceMode::All, FaceMode::Exposed, FaceMode::Merged}) {
    const VoxelMesh m = buildVoxelMesh(g, makeScene(), mode, ColorMode::Count);
    EXPECT_EQ(m.faceCount(), 0u);
    EXPECT_EQ(m.vertexCount(), 0u);
  }
}

TEST(VoxelMesh, SparseGridFarApartUsesLittleMemory) {
  // Two voxels at opposite corners of a 2^20-cell-wide grid: bricks, not a dense array.
  const std::array<uint32_t, 3> dims{1u << 20, 1u << 20, 1u << 20};
  const Grid g = makeGrid(dims, {{0, 0, 0}, {(1 << 20) - 1, (1 << 20) - 1, (1 << 20) - 1}});
  const VoxelMesh m = buildVoxelMesh(g, makeScene(), FaceMode::Merged, ColorMode::None);
  EXPECT_EQ(m.faceCount(), 12u);
  EXPECT_EQ(m.vertexCount(), 16u);
}

// Stops at its call number stopAt (counted from 0) and checks that every fraction lies in [0, 1].
struct StopAt {
  int stopAt = -1;
  std::atomic<int> calls{0};
  std::atomic<bool> outside{false};
  bool operator()(double f) {
    if (!(f >= 0 && f <= 1)) outside = true;
    return calls++ != stopAt;
  }
};

// `work(progress)` throws vox::Error "<what> cancelled" (no subclass) whichever call of `progress` says stop: the
// first, a middle one, the last.
void expectCancels(const std::function<void(const std::function<bool(double)>&)>& work, const std::string& what) {
  StopAt count;
  work(std::ref(count));
  const int total = count.calls;
  EXPECT_GT(total, 20) << what;  // asked often: the binding's Ctrl-C waits on it
  EXPECT_FALSE(count.outside) << what;
  for (int stopAt : {0, 1, total / 3, total / 2, total - 1}) {
    StopAt stop;
    stop.stopAt = stopAt;
    try {
      work(std::ref(stop));
      ADD_FAILURE() << what << ": not cancelled at call " << stopAt << " of " << total;
    } catch (const InputError& e) {
      ADD_FAILURE() << what << ": " << e.what();
    } catch (const LimitError& e) {
      ADD_FAILURE() << what << ": " << e.what();
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), what + " cancelled") << "call " << stopAt << " of " << total;
    }
  }
}

TEST(VoxelMesh, ProgressSaysStopAndTheBuildThrows) {
  std::mt19937 rng(5);
  const std::array<uint32_t, 3> dims{48, 40, 36};
  const IntCellSet cells = randomCells(rng, dims, 0.3);
  const Grid g = makeGrid(dims, cells, {{0, 0, 0}, {47, 39, 35}});
  const Scene scene = makeScene();
  for (FaceMode mode : {FaceMode::All, FaceMode::Exposed, FaceMode::Merged}) {
    const std::string name = faceModeName(mode);
    // A callback that lets it run changes nothing.
    const VoxelMesh plain = buildVoxelMesh(g, scene, mode, ColorMode::Material);
    const VoxelMesh watched = buildVoxelMesh(g, scene, mode, ColorMode::Material, nullptr, [](double) { return true; });
    EXPECT_EQ(watched.vertexCount(), plain.vertexCount()) << name;
    EXPECT_EQ(watched.faceVertices, plain.faceVertices) << name;
    EXPECT_EQ(watched.faceStart, plain.faceStart) << name;
    EXPECT_EQ(watched.faceColors, plain.faceColors) << name;
    expectCancels(
        [&](const std::function<bool(double)>& p) { buildVoxelMesh(g, scene, mode, ColorMode::Material, nullptr, p); },
        "voxel mesh");
    expectCancels([&](const std::function<bool(double)>& p) { triangulateVoxelMesh(plain, p); }, "triangulation");
  }
  for (ColorMode color : {ColorMode::Count, ColorMode::Material}) {
    EXPECT_EQ(occupiedCellColors(g, scene, color, 0, [](double) { return true; }), occupiedCellColors(g, scene, color));
    expectCancels([&](const std::function<bool(double)>& p) { occupiedCellColors(g, scene, color, 0, p); },
                  "cell colours");
  }
}

}  // namespace
}  // namespace vox
