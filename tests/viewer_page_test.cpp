// Tests of the viewer page's binary layout (viewer_page.cpp, docs/viewer-format.md), read back here by a reader
// written from the document, independently of the page's own (viewer/src/data.js, tested by tests/viewer/).
// Checks: the header's fields; every array's offset (a multiple of 8) and the total size; the rows and cells
// giving back the grid's keys, counts and first ids; the surface's triangles being the merged mesh's, placed on
// the lattice, one colour per vertex; widths that follow the data (u8/u16/u32 counts and palette indices, u16/u32
// lattice); the solid runs, the scene's primitives; the signed-distance band and the volume fractions (issue 38),
// whose absence leaves the layout as it was; the level surface of the band (issue 47, flag bit 10) being
// extractLevelSurface's; the HTML around the data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <random>
#include <set>

#include <zlib.h>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/distance/sdf.h"
#include "vox/export/level_surface.h"
#include "vox/export/viewer_page.h"
#include "vox/export/voxel_mesh.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

// A reader of docs/viewer-format.md, version 1.
struct Layout {
  std::string bytes;
  size_t at = kViewerHeaderBytes;

  template <typename T>
  T get(size_t offset) const {
    EXPECT_LE(offset + sizeof(T), bytes.size());
    T v;
    std::memcpy(&v, bytes.data() + offset, sizeof(T));
    return v;
  }
  // The next array: `count` values of `width` bytes, widened to uint64.
  std::vector<uint64_t> take(size_t count, size_t width) {
    EXPECT_EQ(at % 8, 0u);
    std::vector<uint64_t> out(count);
    for (size_t i = 0; i < count; ++i) {
      uint64_t v = 0;
      std::memcpy(&v, bytes.data() + at + i * width, width);
      out[i] = v;
    }
    at = (at + count * width + 7) / 8 * 8;
    EXPECT_LE(at, bytes.size());
    return out;
  }
  template <typename T>
  std::vector<T> takeAs(size_t count) {
    EXPECT_EQ(at % 8, 0u);
    std::vector<T> out(count);
    if (count > 0) std::memcpy(out.data(), bytes.data() + at, count * sizeof(T));  // an empty vector's data() is null
    at = (at + count * sizeof(T) + 7) / 8 * 8;
    EXPECT_LE(at, bytes.size());
    return out;
  }
};

struct Decoded {
  uint32_t flags = 0;
  std::array<uint32_t, 3> dims{};
  uint32_t colorMode = 0, maxCount = 0, vertexCount = 0, triangleCount = 0, paletteCount = 0, rowCount = 0,
           occupied = 0, solidRunCount = 0, idsPerCell = 0, idCount = 0, sceneTriangles = 0, spheres = 0,
           primitives = 0, planes = 0;
  Box bounds;
  Camera camera;
  std::string title;
  std::vector<uint64_t> vertices, vertexColors, triangles, palette, rowKeys, rowStart, cellI, cellCount, cellColor, ids;
  std::vector<double> solidRuns;
  std::vector<float> sceneTriangleCoords, sphereRows;
  // Flags bits 8 and 9: the signed-distance band (header 240-255) and the fractions.
  uint32_t bandCount = 0, bandRowCount = 0;
  double halfWidth = 0;
  std::vector<uint64_t> bandRowKeys, bandRowStart, bandI;
  std::vector<float> distances, fractions;
  // Flag bit 10: the level surface (its counts lead its arrays).
  uint32_t levelVertexCount = 0, levelTriangleCount = 0;
  std::vector<float> levelVertices;
  std::vector<uint32_t> levelTriangles;
  size_t fieldsAt = 0;  // where the fields' arrays start (the end of the layout of a grid without them)
};

size_t widthOf(uint32_t code) { return code == 0 ? 1 : code == 1 ? 2 : 4; }

Decoded decode(const std::string& bytes) {
  Layout l{bytes};
  Decoded d;
  EXPECT_GE(bytes.size(), kViewerHeaderBytes);
  EXPECT_EQ(std::string(bytes.data(), 8), std::string("VOXVIEW\0", 8));
  EXPECT_EQ(l.get<uint32_t>(8), kViewerDataVersion);
  d.flags = l.get<uint32_t>(12);
  for (int a = 0; a < 3; ++a) {
    d.bounds.lo.at(a) = l.get<double>(16 + 8 * a);
    d.bounds.hi.at(a) = l.get<double>(40 + 8 * a);
    d.dims[a] = l.get<uint32_t>(64 + 4 * a);
    d.camera.center.at(a) = l.get<double>(80 + 8 * a);
    d.camera.direction.at(a) = l.get<double>(104 + 8 * a);
    d.camera.up.at(a) = l.get<double>(128 + 8 * a);
  }
  d.colorMode = l.get<uint32_t>(76);
  d.camera.fovDegrees = l.get<double>(152);
  d.camera.orthoHeight = l.get<double>(160);
  d.camera.kind = (d.flags & 64) ? CameraKind::Orthographic : CameraKind::Perspective;
  d.maxCount = l.get<uint32_t>(184);
  d.vertexCount = l.get<uint32_t>(188);
  d.triangleCount = l.get<uint32_t>(192);
  d.paletteCount = l.get<uint32_t>(196);
  d.rowCount = l.get<uint32_t>(200);
  d.occupied = l.get<uint32_t>(204);
  d.solidRunCount = l.get<uint32_t>(208);
  d.idsPerCell = l.get<uint32_t>(212);
  d.idCount = l.get<uint32_t>(216);
  d.sceneTriangles = l.get<uint32_t>(220);
  d.spheres = l.get<uint32_t>(224);
  d.primitives = l.get<uint32_t>(228);
  const uint32_t titleBytes = l.get<uint32_t>(232);
  d.planes = l.get<uint32_t>(236);
  const bool colors = d.flags & 1;
  const size_t coord = (d.flags & 2) ? 4 : 2;
  const size_t countWidth = widthOf((d.flags >> 2) & 3), paletteWidth = widthOf((d.flags >> 4) & 3);
  const auto title = l.take(titleBytes, 1);
  for (uint64_t c : title) d.title += char(c);
  d.vertices = l.take(3 * size_t(d.vertexCount), coord);
  if (colors) d.vertexColors = l.take(3 * size_t(d.vertexCount), 1);
  d.triangles = l.take(3 * size_t(d.triangleCount), 4);
  if (colors) d.palette = l.take(3 * size_t(d.paletteCount), 1);
  d.rowKeys = l.take(d.rowCount, 4);
  d.rowStart = l.take(d.rowCount + 1, 4);
  d.cellI = l.take(d.occupied, coord);
  d.cellCount = l.take(d.occupied, countWidth);
  if (colors) d.cellColor = l.take(d.occupied, paletteWidth);
  d.ids = l.take(d.idCount, 4);
  d.solidRuns = l.takeAs<double>(2 * size_t(d.solidRunCount));
  d.sceneTriangleCoords = l.takeAs<float>(9 * size_t(d.sceneTriangles));
  d.sphereRows = l.takeAs<float>(12 * size_t(d.spheres));
  d.fieldsAt = l.at;
  if (d.flags & 256) {
    d.bandCount = l.get<uint32_t>(240);
    d.bandRowCount = l.get<uint32_t>(244);
    d.halfWidth = l.get<double>(248);
    d.bandRowKeys = l.take(d.bandRowCount, 4);
    d.bandRowStart = l.take(d.bandRowCount + 1, 4);
    d.bandI = l.take(d.bandCount, coord);
    d.distances = l.takeAs<float>(d.bandCount);
  } else {
    for (size_t b = 240; b < kViewerHeaderBytes; ++b) EXPECT_EQ(bytes[b], '\0') << "header byte " << b;
  }
  if (d.flags & 512) d.fractions = l.takeAs<float>(d.occupied);
  if (d.flags & 1024) {
    const auto counts = l.takeAs<uint32_t>(2);
    d.levelVertexCount = counts[0];
    d.levelTriangleCount = counts[1];
    d.levelVertices = l.takeAs<float>(3 * size_t(d.levelVertexCount));
    d.levelTriangles = l.takeAs<uint32_t>(3 * size_t(d.levelTriangleCount));
  }
  EXPECT_EQ(l.at, bytes.size()) << "the layout ends where its last array does";
  return d;
}

// The cells the layout lists, as grid keys, with their counts and stored ids.
void expectCellsMatch(const Decoded& d, const Grid& grid, uint32_t idsPerCell) {
  ASSERT_EQ(d.occupied, grid.occupiedCount());
  ASSERT_EQ(d.rowStart.size(), d.rowCount + 1u);
  EXPECT_EQ(d.rowStart.front(), 0u);
  EXPECT_EQ(d.rowStart.back(), d.occupied);
  size_t id = 0;
  uint32_t maxCount = 0;
  for (size_t r = 0; r < d.rowCount; ++r) {
    if (r > 0) {
      EXPECT_LT(d.rowKeys[r - 1], d.rowKeys[r]);
    }
    ASSERT_LT(d.rowStart[r], d.rowStart[r + 1]) << "a row holds at least one cell";
    for (uint64_t c = d.rowStart[r]; c < d.rowStart[r + 1]; ++c) {
      EXPECT_EQ(d.cellI[c] + uint64_t(grid.dims[0]) * d.rowKeys[r], grid.cellKeys[c]);
      const auto prims = grid.cellPrims(c);
      EXPECT_EQ(d.cellCount[c], prims.size());
      maxCount = std::max<uint32_t>(maxCount, uint32_t(prims.size()));
      for (size_t i = 0; i < std::min<size_t>(prims.size(), idsPerCell); ++i) EXPECT_EQ(d.ids[id++], prims[i]);
    }
  }
  EXPECT_EQ(id, d.idCount);
  EXPECT_EQ(d.maxCount, maxCount);
  ASSERT_EQ(d.solidRuns.size(), 2 * grid.solidRuns.size());
  for (size_t r = 0; r < grid.solidRuns.size(); ++r) {
    EXPECT_EQ(d.solidRuns[2 * r], double(grid.solidRuns[r].first));
    EXPECT_EQ(d.solidRuns[2 * r + 1], double(grid.solidRuns[r].count));
  }
}

// The surface: the triangles of triangulateVoxelMesh(buildVoxelMesh(Merged)), in order, on the lattice, each
// vertex of one colour (the face's). Also: their area in lattice units is the number of exposed unit squares.
void expectSurfaceMatches(const Decoded& d, const Grid& grid, const Scene& scene, ColorMode color) {
  VoxelMeshStats stats;
  const VoxelMesh mesh = triangulateVoxelMesh(buildVoxelMesh(grid, scene, FaceMode::Merged, color, &stats));
  ASSERT_EQ(d.triangleCount, mesh.faceCount());
  double area2 = 0;  // twice the area, lattice units
  std::set<std::array<uint64_t, 6>> distinct;
  for (size_t f = 0; f < mesh.faceCount(); ++f) {
    std::array<std::array<double, 3>, 3> p{};
    for (int c = 0; c < 3; ++c) {
      const uint64_t v = d.triangles[3 * f + c];
      ASSERT_LT(v, d.vertexCount);
      const Vec3& want = mesh.positions[mesh.faceVertices[mesh.faceStart[f] + c]];
      for (int a = 0; a < 3; ++a) {
        p[c][a] = double(d.vertices[3 * v + a]);
        EXPECT_EQ(cellBoundary(grid.bounds, grid.dims, a, int64_t(d.vertices[3 * v + a])), want[a]);
      }
      if (color != ColorMode::None) {
        const Rgb8& fc = mesh.faceColors[f];
        for (int k = 0; k < 3; ++k) EXPECT_EQ(d.vertexColors[3 * v + k], fc[k]);
        distinct.insert({d.vertices[3 * v], d.vertices[3 * v + 1], d.vertices[3 * v + 2], fc[0], fc[1], fc[2]});
      }
    }
    const Vec3 e1{p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const Vec3 e2{p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    area2 += length(cross(e1, e2));
  }
  EXPECT_DOUBLE_EQ(area2 / 2, double(stats.exposedFaces));
  if (color != ColorMode::None) {
    EXPECT_EQ(distinct.size(), d.vertexCount) << "one page vertex per point and colour";
  }
}

Scene voxelizedBox(Grid& grid, std::array<uint32_t, 3> dims, bool fill) {
  Scene scene = testing::boxScene(0.1, 0.9);
  scene.spheres.push_back({{0.5, 0.5, 0.5}, 0.2, translation({0.01, 0, 0}) * scaling({1, 0.5, 1}), 0});
  VoxelizeOptions options;
  options.dims = dims;
  grid = voxelizeScene(scene, options);
  if (fill) fillSolid(grid, scene);
  return scene;
}

TEST(ViewerPage, LayoutOfAVoxelizedBoxWithSphereAndFill) {
  for (bool fill : {false, true}) {
    Grid grid;
    const Scene scene = voxelizedBox(grid, {9, 7, 5}, fill);
    ASSERT_EQ(!grid.solidRuns.empty(), fill);
    ViewerPageOptions options;
    options.title = "box.vgrid";
    options.idsPerCell = 3;
    ViewerDataStats stats;
    const std::string bytes = encodeViewerData(grid, scene, options, &stats);
    const Decoded d = decode(bytes);
    EXPECT_EQ(d.title, "box.vgrid");
    EXPECT_EQ(d.dims, grid.dims);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(d.bounds.lo[a], grid.bounds.lo[a]);
      EXPECT_EQ(d.bounds.hi[a], grid.bounds.hi[a]);
    }
    EXPECT_EQ(d.flags & 3, 1u) << "colours, narrow lattice";
    EXPECT_EQ(d.colorMode, 0u);
    EXPECT_EQ(d.idsPerCell, 3u);
    // The scene has no camera: the page gets the one vox-trace uses.
    const Camera want = defaultCamera(grid.bounds);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(d.camera.center[a], want.center[a]);
      EXPECT_EQ(d.camera.direction[a], want.direction[a]);
      EXPECT_EQ(d.camera.up[a], want.up[a]);
    }
    EXPECT_EQ(d.camera.fovDegrees, want.fovDegrees);
    expectCellsMatch(d, grid, 3);
    expectSurfaceMatches(d, grid, scene, ColorMode::Count);
    // Cell colours: the palette entries are the exporters' colours.
    const std::vector<Rgb8> colors = occupiedCellColors(grid, scene, ColorMode::Count);
    for (size_t c = 0; c < grid.occupiedCount(); ++c)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(d.palette[3 * d.cellColor[c] + k], colors[c][k]);
    // Scene primitives relative to the bounds' centre.
    const Vec3 centre = (grid.bounds.lo + grid.bounds.hi) * 0.5;
    ASSERT_EQ(d.sceneTriangles, scene.triangles.size());
    for (size_t t = 0; t < scene.triangles.size(); ++t)
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a)
          EXPECT_EQ(d.sceneTriangleCoords[9 * t + 3 * v + a], float(scene.triangles[t].v[v][a] - centre[a]));
    ASSERT_EQ(d.spheres, 1u);
    // The unit sphere's point (1, 0, 0) lands on the ellipsoid: transform * (centre + radius * (1, 0, 0)).
    const Sphere& s = scene.spheres[0];
    const Vec3 onSurface = transformPoint(s.transform, s.center + Vec3{s.radius, 0, 0}) - centre;
    for (int r = 0; r < 3; ++r) EXPECT_NEAR(d.sphereRows[4 * r] + d.sphereRows[4 * r + 3], onSurface[r], 1e-6);
    EXPECT_EQ(d.primitives, scene.primitiveCount());
    EXPECT_EQ(stats.voxels, grid.occupiedCount() + grid.solidCount());
    EXPECT_EQ(stats.surfaceTriangles, d.triangleCount);
    EXPECT_EQ(stats.dataBytes, bytes.size());
  }
}

TEST(ViewerPage, MaterialAndNoColours) {
  Grid grid;
  Scene scene = voxelizedBox(grid, {6, 6, 6}, false);
  Material red;
  red.diffuse = {1, 0, 0};
  scene.materials.push_back(red);
  for (size_t t = 0; t < scene.triangles.size(); t += 2) scene.triangles[t].material = 1;
  ViewerPageOptions options;
  options.color = ColorMode::Material;
  Decoded d = decode(encodeViewerData(grid, scene, options));
  EXPECT_EQ(d.colorMode, 1u);
  expectSurfaceMatches(d, grid, scene, ColorMode::Material);
  const std::vector<Rgb8> colors = occupiedCellColors(grid, scene, ColorMode::Material);
  std::set<std::array<uint8_t, 3>> seen;
  for (size_t c = 0; c < grid.occupiedCount(); ++c) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(d.palette[3 * d.cellColor[c] + k], colors[c][k]);
    seen.insert(colors[c]);
  }
  EXPECT_EQ(d.paletteCount, seen.size()) << "the palette holds each colour once";
  EXPECT_GE(seen.size(), 2u);

  options.color = ColorMode::None;
  d = decode(encodeViewerData(grid, scene, options));
  EXPECT_EQ(d.flags & 1, 0u);
  EXPECT_EQ(d.colorMode, 2u);
  EXPECT_TRUE(d.palette.empty());
  expectSurfaceMatches(d, grid, scene, ColorMode::None);
  expectCellsMatch(d, grid, options.idsPerCell);
}

// Hand-made grids for the extremes: empty, one cell, a wide lattice, many primitives in a cell, many colours.
Grid handGrid(std::array<uint32_t, 3> dims, const std::vector<std::array<uint32_t, 3>>& cells,
              const std::vector<uint32_t>& counts) {
  Grid g;
  g.dims = dims;
  g.bounds = {{-1, 0, 2}, {-1 + 0.5 * dims[0], 0.25 * dims[1], 2 + 2.0 * dims[2]}};
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  for (size_t c = 0; c < cells.size(); ++c)
    keyed.push_back({cellKey(dims, cells[c][0], cells[c][1], cells[c][2]), counts[c]});
  std::sort(keyed.begin(), keyed.end());
  for (const auto& [key, n] : keyed) {
    g.cellKeys.push_back(key);
    for (uint32_t p = 0; p < n; ++p) g.primIds.push_back(p);
    g.cellStart.push_back(g.primIds.size());
  }
  return g;
}

Scene trianglesScene(size_t n) {
  Scene s;
  s.materials.push_back({});
  for (size_t i = 0; i < n; ++i) s.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, 0});
  return s;
}

TEST(ViewerPage, EmptyGridIsHeaderAndTitle) {
  const Grid grid = handGrid({1, 1, 1}, {}, {});
  ViewerPageOptions options;
  options.title = "empty";
  const std::string bytes = encodeViewerData(grid, Scene{}, options);
  EXPECT_EQ(bytes.size(), kViewerHeaderBytes + 8 + 8) << "the header, the title and the one row start";
  const Decoded d = decode(bytes);
  EXPECT_EQ(d.occupied + d.vertexCount + d.triangleCount + d.rowCount + d.idCount, 0u);
}

TEST(ViewerPage, WidthsFollowTheData) {
  // 70000 cells along x: the lattice needs u32; a cell of 300 primitives: counts in u16.
  Grid grid = handGrid({70000, 1, 1}, {{0, 0, 0}, {69999, 0, 0}, {5, 0, 0}}, {1, 300, 2});
  Decoded d = decode(encodeViewerData(grid, trianglesScene(300), {}));
  EXPECT_EQ(d.flags & 2, 2u);
  EXPECT_EQ((d.flags >> 2) & 3, 1u);
  expectCellsMatch(d, grid, 4);
  expectSurfaceMatches(d, grid, trianglesScene(300), ColorMode::Count);
  EXPECT_EQ(d.cellI.back(), 69999u);

  // 2048 x 3 x 1 with every cell occupied, counts up to 70000: u16 lattice, u32 counts.
  std::vector<std::array<uint32_t, 3>> cells;
  std::vector<uint32_t> counts;
  for (uint32_t j = 0; j < 3; ++j)
    for (uint32_t i = 0; i < 2048; ++i)
      cells.push_back({i, j, 0}), counts.push_back(i == 7 && j == 1 ? 70000 : 1 + i % 5);
  grid = handGrid({2048, 3, 1}, cells, counts);
  const Scene many = trianglesScene(70000);
  d = decode(encodeViewerData(grid, many, {}));
  EXPECT_EQ(d.flags & 2, 0u);
  EXPECT_EQ((d.flags >> 2) & 3, 2u);
  EXPECT_EQ(d.rowCount, 3u);
  expectCellsMatch(d, grid, 4);
  expectSurfaceMatches(d, grid, many, ColorMode::Count);
  // Without colours the box of voxels merges into six rectangles, two triangles each (with count colours, which
  // vary from cell to cell, it cannot).
  ViewerPageOptions plain;
  plain.color = ColorMode::None;
  EXPECT_EQ(decode(encodeViewerData(grid, many, plain)).triangleCount, 12u);
  EXPECT_GT(d.triangleCount, 12u);

  // More than 256 colours (material mode, one material per cell): u16 palette indices.
  Scene colorful;
  std::vector<std::array<uint32_t, 3>> row;
  for (uint32_t i = 0; i < 300; ++i) {
    Material m;
    m.diffuse = {(i % 20) / 19.0, (i / 20) / 14.0, 0.5};
    colorful.materials.push_back(m);
    colorful.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}, i});
    row.push_back({i, 0, 0});
  }
  grid = handGrid({300, 1, 1}, row, std::vector<uint32_t>(300, 1));
  for (size_t c = 0; c < 300; ++c) grid.primIds[c] = uint32_t(c);
  ViewerPageOptions options;
  options.color = ColorMode::Material;
  d = decode(encodeViewerData(grid, colorful, options));
  EXPECT_EQ((d.flags >> 4) & 3, 1u);
  EXPECT_GT(d.paletteCount, 256u);
  expectSurfaceMatches(d, grid, colorful, ColorMode::Material);
}

TEST(ViewerPage, IdsPerCellLimitsTheStoredIds) {
  const Grid grid = handGrid({4, 4, 4}, {{0, 0, 0}, {1, 2, 3}, {3, 3, 3}}, {1, 9, 4});
  for (uint32_t k : {0u, 1u, 4u, 20u}) {
    ViewerPageOptions options;
    options.idsPerCell = k;
    const Decoded d = decode(encodeViewerData(grid, trianglesScene(9), options));
    EXPECT_EQ(d.idCount, std::min(1u, k) + std::min(9u, k) + std::min(4u, k));
    expectCellsMatch(d, grid, k);
  }
}

TEST(ViewerPage, OrthographicCameraAndBackgroundAreKept) {
  const Grid grid = handGrid({2, 2, 2}, {{1, 1, 1}}, {1});
  Scene scene = trianglesScene(1);
  Camera cam;
  cam.kind = CameraKind::Orthographic;
  cam.center = {1, 2, 3};
  cam.direction = {0, -1, 0};
  cam.up = {0, 0, 1};
  cam.orthoHeight = 7.5;
  scene.camera = cam;
  scene.background = {0.25, 0.5, 1};
  const std::string bytes = encodeViewerData(grid, scene, {});
  const Decoded d = decode(bytes);
  EXPECT_EQ(d.camera.kind, CameraKind::Orthographic);
  EXPECT_EQ(d.camera.orthoHeight, 7.5);
  EXPECT_EQ(d.camera.center[1], 2);
  EXPECT_EQ(d.camera.up[2], 1);
  Layout l{bytes};
  EXPECT_EQ(l.get<float>(168), 0.25f);
  EXPECT_EQ(l.get<float>(176), 1.0f);
}

TEST(ViewerPage, InconsistentGridIsRefused) {
  Grid grid = handGrid({2, 2, 2}, {{1, 1, 1}}, {1});
  grid.cellStart.push_back(5);
  EXPECT_THROW(encodeViewerData(grid, trianglesScene(1), {}), InputError);
}

// A band and fractions made up for the test (the layout does not care where they come from): every third cell of
// the grid in key order, distances from the key, fractions from the cell's index.
void addFields(Grid& grid, double halfWidth) {
  grid.sdfHalfWidth = halfWidth;
  for (uint64_t key = 1; key < grid.cellCount(); key += 3) {
    grid.sdfKeys.push_back(key);
    grid.sdfValues.push_back((double(key) - 100.3) / 7.0);
  }
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) grid.fractions.push_back(double(c % 11) / 10.0 + 1e-9);
}

TEST(ViewerPage, DistancesAndFractionsFollowTheArrays) {
  Grid grid;
  const Scene scene = voxelizedBox(grid, {9, 7, 5}, true);
  const std::string plain = encodeViewerData(grid, scene, {});
  addFields(grid, 2.5);
  const Decoded d = decode(encodeViewerData(grid, scene, {}));
  EXPECT_EQ(d.flags & 768, 768u);
  EXPECT_EQ(d.halfWidth, 2.5);
  ASSERT_EQ(d.bandCount, grid.sdfKeys.size());
  ASSERT_EQ(d.bandRowStart.size(), d.bandRowCount + 1u);
  EXPECT_EQ(d.bandRowStart.back(), d.bandCount);
  for (size_t r = 0; r < d.bandRowCount; ++r) {
    if (r > 0) {
      EXPECT_LT(d.bandRowKeys[r - 1], d.bandRowKeys[r]);
    }
    ASSERT_LT(d.bandRowStart[r], d.bandRowStart[r + 1]) << "a row holds at least one band cell";
    for (uint64_t b = d.bandRowStart[r]; b < d.bandRowStart[r + 1]; ++b) {
      EXPECT_EQ(d.bandI[b] + uint64_t(grid.dims[0]) * d.bandRowKeys[r], grid.sdfKeys[b]);
      EXPECT_EQ(d.distances[b], float(grid.sdfValues[b]));
    }
  }
  ASSERT_EQ(d.fractions.size(), grid.cellKeys.size());
  for (size_t c = 0; c < grid.cellKeys.size(); ++c) EXPECT_EQ(d.fractions[c], float(grid.fractions[c]));

  // Without the fields the layout is the one above up to where they start, with flags bits 8-9 and bytes 240-255
  // cleared: pages of grids without them did not change.
  std::string stripped = encodeViewerData(grid, scene, {}).substr(0, d.fieldsAt);
  const uint32_t flags = d.flags & ~1792u;
  std::memcpy(stripped.data() + 12, &flags, 4);
  std::fill(stripped.begin() + 240, stripped.begin() + kViewerHeaderBytes, '\0');
  EXPECT_EQ(stripped, plain);

  // A grid asked for distances whose band came out empty still says so (bit 8, zero counts); fractions alone.
  Grid empty = grid;
  empty.sdfKeys.clear();
  empty.sdfValues.clear();
  empty.fractions.clear();
  const Decoded e = decode(encodeViewerData(empty, scene, {}));
  EXPECT_EQ(e.flags & 768, 256u);
  EXPECT_EQ(e.bandCount, 0u);
  EXPECT_EQ(e.bandRowStart, std::vector<uint64_t>{0});
  Grid onlyFractions = grid;
  onlyFractions.sdfHalfWidth = 0;
  onlyFractions.sdfKeys.clear();
  onlyFractions.sdfValues.clear();
  const Decoded f = decode(encodeViewerData(onlyFractions, scene, {}));
  EXPECT_EQ(f.flags & 768, 512u);
  EXPECT_EQ(f.fractions.size(), grid.cellKeys.size());
}

// The level surface d = 0 (flag bit 10) is extractLevelSurface's, positions as float relative to the bounds'
// centre; a band too narrow for level 0 (narrower than a cell's diagonal) and a grid without a band have none.
TEST(ViewerPage, LevelSurfaceFollowsTheFields) {
  Grid grid;
  const Scene scene = voxelizedBox(grid, {9, 7, 5}, false);
  SdfOptions options;
  options.halfWidth = 3;
  storeSignedDistances(grid, scene, options, false);
  ASSERT_GE(largestSurfaceLevel(grid), 0);
  const VoxelMesh level = extractLevelSurface(grid, 0);
  ASSERT_GT(level.faceCount(), 0u);
  ViewerDataStats stats;
  const Decoded d = decode(encodeViewerData(grid, scene, {}, &stats));
  EXPECT_EQ(d.flags & 1792, 1792u & ~512u);
  ASSERT_EQ(d.levelVertexCount, level.vertexCount());
  ASSERT_EQ(d.levelTriangleCount, level.faceCount());
  EXPECT_EQ(stats.levelTriangles, level.faceCount());
  const Vec3 centre = (grid.bounds.lo + grid.bounds.hi) * 0.5;
  for (size_t v = 0; v < level.vertexCount(); ++v)
    for (int a = 0; a < 3; ++a)
      ASSERT_EQ(d.levelVertices[3 * v + size_t(a)], float(level.positions[v][a] - centre[a])) << v;
  EXPECT_EQ(d.levelTriangles, level.faceVertices);

  Grid narrow = grid;
  narrow.sdfHalfWidth = 1;  // 1 cell < the diagonal: --surface refuses level 0, the page has no surface
  ASSERT_LT(largestSurfaceLevel(narrow), 0);
  EXPECT_EQ(decode(encodeViewerData(narrow, scene, {})).flags & 1024, 0u);
  Grid plain;
  const Scene plainScene = voxelizedBox(plain, {9, 7, 5}, false);
  EXPECT_EQ(decode(encodeViewerData(plain, plainScene, {})).flags & 1792, 0u);
}

TEST(ViewerPage, FieldsThatDoNotFitTheGridAreRefused) {
  Grid grid;
  const Scene scene = voxelizedBox(grid, {9, 7, 5}, false);
  addFields(grid, 3);
  const auto refused = [&](auto change, const char* what) {
    Grid bad = grid;
    change(bad);
    EXPECT_THROW(encodeViewerData(bad, scene, {}), InputError) << what;
  };
  refused([](Grid& g) { g.sdfValues.pop_back(); }, "fewer values than keys");
  refused([](Grid& g) { std::swap(g.sdfKeys[0], g.sdfKeys[1]); }, "keys not ascending");
  refused([](Grid& g) { g.sdfKeys.back() = g.cellCount(); }, "a key outside the grid");
  refused([](Grid& g) { g.sdfHalfWidth = 0; }, "a band without a half-width");
  refused([](Grid& g) { g.fractions.pop_back(); }, "fractions for fewer cells");
}

std::string decodeBase64(const std::string& text) {
  static const std::array<int, 256> value = [] {
    std::array<int, 256> v;
    v.fill(-1);
    const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int i = 0; i < 64; ++i) v[uint8_t(alphabet[i])] = i;
    return v;
  }();
  std::string out;
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    const int x = value[uint8_t(c)];
    if (x < 0) continue;
    acc = acc << 6 | uint32_t(x);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((acc >> bits) & 0xff);
    }
  }
  return out;
}

// The data elements of a page: their base64 texts joined and decoded, then inflated (the elements say
// data-encoding="deflate" and the layout's size in data-bytes). `chunks` counts the elements.
std::string pageLayout(const std::string& page, size_t& chunks, size_t& firstStart, size_t& lastEnd) {
  const std::string open = "<script type=\"application/x-vox-data\" data-encoding=\"deflate\" data-bytes=\"";
  std::string joined;
  uLong bytes = 0;
  chunks = 0;
  firstStart = page.find(open);
  for (size_t at = firstStart; at != std::string::npos; at = page.find(open, at + 1)) {
    const size_t tagEnd = page.find("\">", at);
    bytes = std::stoul(page.substr(at + open.size(), tagEnd - at - open.size()));
    const size_t close = page.find("</script>", at);
    const std::string text = page.substr(tagEnd + 2, close - tagEnd - 2);
    EXPECT_EQ(text.size() % 4, 0u);
    if (chunks > 0) {
      EXPECT_EQ(joined.size() % 3, 0u) << "only the last chunk may need padding";
    }
    joined += decodeBase64(text);
    ++chunks;
    lastEnd = close;
  }
  std::string out(bytes, '\0');
  uLong size = bytes;
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(joined.data()),
                       uLong(joined.size())),
            Z_OK);
  EXPECT_EQ(size, bytes);
  return out;
}

TEST(ViewerPage, HtmlHoldsTheDataAndTheScript) {
  if (!viewerPageAvailable()) {
    EXPECT_THROW(viewerPageHtml("x", "t"), UsageError);
    GTEST_SKIP() << "built with VOX_VIEWER=OFF";
  }
  Grid grid;
  const Scene scene = voxelizedBox(grid, {5, 5, 5}, false);
  const std::string data = encodeViewerData(grid, scene, {});
  const std::string html = viewerPageHtml(data, "a<b>&\"c\".vgrid");
  EXPECT_NE(html.find("<title>a&lt;b&gt;&amp;&quot;c&quot;.vgrid - libvox viewer</title>"), std::string::npos);
  EXPECT_NE(html.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
  size_t chunks = 0, start = 0, end = 0;
  EXPECT_EQ(pageLayout(html, chunks, start, end), data);
  EXPECT_EQ(chunks, 1u);
  const size_t script = html.find("<script type=\"module\">");
  ASSERT_NE(script, std::string::npos);
  ASSERT_NE(start, std::string::npos);
  const std::string skeleton = html.substr(0, start) + html.substr(end, script - end);
  for (const char* link : {"src=", "href=", "<link", "url(", "http:", "https:"})
    EXPECT_EQ(skeleton.find(link), std::string::npos) << "nothing to fetch: " << link;
  // Data that does not compress: several chunks, each a base64 text of its own, together the deflated data.
  std::string big(size_t(100) << 20, '\0');
  std::mt19937 rng(7);
  for (char& c : big) c = char(rng());
  const std::string page = viewerPageHtml(big, "big");
  EXPECT_TRUE(pageLayout(page, chunks, start, end) == big);
  EXPECT_EQ(chunks, 3u);
}

}  // namespace
}  // namespace vox
