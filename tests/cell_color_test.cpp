// Tests for voxel colours under --color material (export/cell_color.cpp) and
// what they rest on: triangle-box clipping (clip_triangle.cpp) and
// area-weighted texture averages (texture_average.cpp).
#include "vox/export/cell_color.h"

#include <gtest/gtest.h>

#include "core/clip_triangle.h"
#include "vox/core/texture_average.h"
#include "vox/core/error.h"
#include "vox/export/voxel_mesh.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

double polygonArea(const ClipPolygon& p) {
  double a = 0;
  for (size_t k = 1; k + 1 < p.size; ++k) a += 0.5 * length(cross(p.v[k].p - p.v[0].p, p.v[k + 1].p - p.v[0].p));
  return a;
}

TEST(ClipTriangle, AreasAndBarycentricsFollowTheClip) {
  const std::array<Vec3, 3> t{Vec3{0, 0, 0.5}, Vec3{4, 0, 0.5}, Vec3{0, 4, 0.5}};
  // Fully inside: unchanged.
  EXPECT_DOUBLE_EQ(polygonArea(clipTriangleToBox(t, {{-1, -1, 0}, {5, 5, 1}})), 8);
  // The unit square at the corner: area 1, a quadrilateral.
  const ClipPolygon corner = clipTriangleToBox(t, {{0, 0, 0}, {1, 1, 1}});
  EXPECT_EQ(corner.size, 4u);
  EXPECT_DOUBLE_EQ(polygonArea(corner), 1);
  // The square [1,3]^2 holds the part below x + y = 4: area 4 - 2 = 2 (a
  // triangle cut off).
  const ClipPolygon mid = clipTriangleToBox(t, {{1, 1, 0}, {3, 3, 1}});
  EXPECT_DOUBLE_EQ(polygonArea(mid), 2);
  // Every clipped vertex is the barycentric combination of the corners, and
  // lies in the box.
  for (size_t k = 0; k < mid.size; ++k) {
    const ClipVertex& v = mid.v[k];
    const Vec3 p = t[0] * v.bary.x + t[1] * v.bary.y + t[2] * v.bary.z;
    EXPECT_NEAR(length(p - v.p), 0, 1e-12);
    EXPECT_NEAR(v.bary.x + v.bary.y + v.bary.z, 1, 1e-12);
    for (int a = 0; a < 3; ++a) EXPECT_TRUE(v.p[a] >= (a == 2 ? 0 : 1) && v.p[a] <= (a == 2 ? 1 : 3));
  }
  // Outside: empty. Touching along an edge: no area.
  EXPECT_EQ(clipTriangleToBox(t, {{5, 5, 0}, {6, 6, 1}}).size, 0u);
  EXPECT_EQ(polygonArea(clipTriangleToBox(t, {{-1, -1, 0.5}, {5, 5, 2}})), 8);
  EXPECT_EQ(polygonArea(clipTriangleToBox(t, {{-1, -1, 0.5 + 1e-9}, {5, 5, 2}})), 0);
}

TEST(ClipTriangle, NearestBarycentric) {
  const std::array<Vec3, 3> t{Vec3{0, 0, 0}, Vec3{2, 0, 0}, Vec3{0, 2, 0}};
  const Vec3 inside = nearestBarycentric(t, {0.5, 0.5, 3});
  EXPECT_NEAR(inside.y, 0.25, 1e-15);
  EXPECT_NEAR(inside.z, 0.25, 1e-15);
  EXPECT_EQ(nearestBarycentric(t, {-1, -1, 0}).x, 1);
  const Vec3 edge = nearestBarycentric(t, {1, -5, 0});
  EXPECT_NEAR(edge.y, 0.5, 1e-15);
  EXPECT_EQ(edge.z, 0);
  const Vec3 degenerate = nearestBarycentric({Vec3{1, 1, 1}, Vec3{1, 1, 1}, Vec3{1, 1, 1}}, {0, 0, 0});
  EXPECT_NEAR(degenerate.x + degenerate.y + degenerate.z, 1, 1e-15);
}

// A 2x2 texture: left column red, right column blue, clamped.
Texture redBlue() {
  Texture t;
  t.width = 2;
  t.height = 2;
  t.rgb = {255, 0, 0, 0, 0, 255, 255, 0, 0, 0, 0, 255};
  t.wrapU = t.wrapV = TextureWrap::ClampToEdge;
  return t;
}

// The quad [0,2] x [0,1] in z = 0 as two triangles, u = x / 2, v = 1 - y.
Scene texturedQuad() {
  Scene scene;
  Material m{"tex"};
  m.diffuseTexture = 0;
  scene.materials.push_back(m);
  scene.textures.push_back(redBlue());
  const Vec3 a{0, 0, 0}, b{2, 0, 0}, c{2, 1, 0}, d{0, 1, 0};
  scene.triangles.push_back({{a, b, c}, 0});
  scene.triangles.push_back({{a, c, d}, 0});
  auto uv = [](const Vec3& p) { return TexCoord{p.x / 2, 1 - p.y}; };
  scene.triangleUVs.push_back({uv(a), uv(b), uv(c)});
  scene.triangleUVs.push_back({uv(a), uv(c), uv(d)});
  return scene;
}

Vec3 colorAt(const Grid& grid, const Scene& scene, uint32_t i, uint32_t j, uint32_t k) {
  const int64_t c = findCell(grid, cellKey(grid.dims, i, j, k));
  EXPECT_GE(c, 0);
  return c < 0 ? Vec3{-1, -1, -1} : cellMaterialColor(grid, scene, size_t(c));
}

TEST(CellColor, TextureAveragedOverTheCellsPartOfEachTriangle) {
  Scene scene = texturedQuad();
  VoxelizeOptions options;
  options.bounds = Box{{0, 0, -0.5}, {2, 1, 0.5}};
  options.dims = std::array<uint32_t, 3>{4, 1, 1};
  const Grid grid = voxelizeScene(scene, options);
  ASSERT_EQ(grid.cellKeys.size(), 4u);
  // Cell 0 (u in [0, 0.25]) lies left of the first texel centre: pure red. Cell
  // 3 pure blue.
  const Vec3 c0 = colorAt(grid, scene, 0, 0, 0), c3 = colorAt(grid, scene, 3, 0, 0);
  EXPECT_NEAR(c0.x, 1, 1e-12);
  EXPECT_NEAR(c0.z, 0, 1e-12);
  EXPECT_NEAR(c3.x, 0, 1e-12);
  EXPECT_NEAR(c3.z, 1, 1e-12);
  // Cell 1 (u in [0.25, 0.5]) blends linearly from red to half and half: mean
  // blue weight 1/4 in linear light.
  const Vec3 c1 = colorAt(grid, scene, 1, 0, 0), c2 = colorAt(grid, scene, 2, 0, 0);
  EXPECT_NEAR(c1.x, linearToSrgb(0.75), 0.01);
  EXPECT_NEAR(c1.z, linearToSrgb(0.25), 0.01);
  EXPECT_NEAR(c2.x, c1.z, 1e-9);  // mirror images
  EXPECT_NEAR(c2.z, c1.x, 1e-9);
  // The factor multiplies the texture's colour; without the texture the factor
  // alone is the colour.
  scene.materials[0].diffuse = {0.5, 1, 1};
  EXPECT_NEAR(colorAt(grid, scene, 0, 0, 0).x, 0.5, 1e-12);
  scene.materials[0].diffuseTexture = kNoTexture;
  EXPECT_EQ(colorAt(grid, scene, 3, 0, 0).x, 0.5);
  EXPECT_EQ(colorAt(grid, scene, 3, 0, 0).z, 1);
}

TEST(CellColor, CoarseCellsAverageEveryTexelTheyCover) {
  // A 64x64 checkerboard of black and white texels on a quad filling one cell:
  // the mean is half the light.
  Scene scene = texturedQuad();
  Texture& t = scene.textures[0];
  t.width = t.height = 64;
  t.rgb.assign(64 * 64 * 3, 0);
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x)
      if ((x + y) % 2) std::fill_n(&t.rgb[(y * 64 + x) * 3], 3, uint8_t(255));
  VoxelizeOptions options;
  options.dims = std::array<uint32_t, 3>{1, 1, 1};
  const Grid grid = voxelizeScene(scene, options);
  ASSERT_EQ(grid.cellKeys.size(), 1u);
  const Vec3 c = cellMaterialColor(grid, scene, 0);
  EXPECT_NEAR(c.x, linearToSrgb(0.5), 0.03);
  EXPECT_NEAR(c.y, c.x, 1e-12);
}

TEST(CellColor, MajorityMaterialAndEdgeContacts) {
  Scene scene = texturedQuad();
  // A third triangle of an untextured green material crossing the same cells.
  scene.materials.push_back(Material{"green"});
  scene.materials[1].diffuse = {0, 1, 0};
  scene.triangles.push_back({{Vec3{0, 0, 0.1}, Vec3{2, 0, 0.1}, Vec3{0, 1, 0.1}}, 1});
  scene.triangleUVs.push_back({});
  VoxelizeOptions options;
  options.bounds = Box{{0, 0, -0.5}, {2, 1, 0.5}};
  options.dims = std::array<uint32_t, 3>{4, 1, 1};
  const Grid grid = voxelizeScene(scene, options);
  // Cell 0 holds both textured triangles (2 votes) and the green one (1): the
  // texture wins.
  EXPECT_NEAR(colorAt(grid, scene, 0, 0, 0).x, 1, 1e-12);
  // A cell that only touches the textured quad along its edge x = 0 gets the
  // texture at the nearest point (red); the cell beyond x = 2 gets blue.
  Scene touching = texturedQuad();
  options.bounds = Box{{-1, 0, -0.5}, {3, 1, 0.5}};
  options.dims = std::array<uint32_t, 3>{4, 1, 1};
  const Grid g2 = voxelizeScene(touching, options);
  ASSERT_EQ(g2.cellKeys.size(), 4u);
  EXPECT_NEAR(colorAt(g2, touching, 0, 0, 0).x, 1, 1e-12);
  EXPECT_NEAR(colorAt(g2, touching, 0, 0, 0).z, 0, 1e-12);
  EXPECT_NEAR(colorAt(g2, touching, 3, 0, 0).z, 1, 1e-12);
  // Out-of-range material indices are errors, not crashes.
  touching.triangles[0].material = touching.triangles[1].material = 9;
  EXPECT_THROW(cellMaterialColor(g2, touching, 0), InputError);
}

}  // namespace
}  // namespace vox
