// Voxel colours for --color material (cell_color.h).
#include "vox/export/cell_color.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "vox/core/texture_average.h"
#include "vox/core/error.h"
#include "vox/export/voxel_mesh.h"

namespace vox {

namespace {

uint32_t materialOf(const Scene& scene, uint32_t prim) {
  const size_t t = scene.triangles.size(), s = scene.spheres.size(), p = scene.planes.size();
  if (prim < t) return scene.triangles[prim].material;
  if (prim < t + s) return scene.spheres[prim - t].material;
  if (prim < t + s + p) return scene.planes[prim - t - s].material;
  fail<InputError>("grid: primitive id ", prim, " out of range (", t + s + p, " primitives)");
}

// The texture of `material` averaged over its triangles in `cell` (linear
// light); false when none is sampled.
bool textureAverage(const Grid& grid, const Scene& scene, size_t cell, uint32_t material, Vec3& out) {
  const Texture& texture = scene.textures[scene.materials[material].diffuseTexture];
  const auto ijk = cellIndex(grid.dims, grid.cellKeys[cell]);
  const Box box = cellBox(grid, ijk[0], ijk[1], ijk[2]);
  TextureSum sum;
  for (uint32_t prim : grid.cellPrims(cell))
    if (prim < scene.triangles.size() && scene.triangles[prim].material == material)
      addTextureOverBox(texture, scene.triangles[prim].v, scene.triangleUVs[prim], box, sum);
  if (sum.empty()) return false;
  out = sum.average();
  return true;
}

}  // namespace

Vec3 cellMaterialColor(const Grid& grid, const Scene& scene, size_t cell) {
  // Cells hold few primitives: a small linear tally beats a map.
  std::vector<std::pair<uint32_t, uint32_t>> tally;
  for (uint32_t prim : grid.cellPrims(cell)) {
    const uint32_t m = materialOf(scene, prim);
    auto it = std::find_if(tally.begin(), tally.end(), [&](const auto& e) { return e.first == m; });
    if (it == tally.end())
      tally.push_back({m, 1});
    else
      ++it->second;
  }
  if (tally.empty())
    return Vec3{double(kSolidCellColor[0]), double(kSolidCellColor[1]), double(kSolidCellColor[2])} / 255.0;
  std::pair<uint32_t, uint32_t> best = tally[0];
  for (const auto& e : tally)
    if (e.second > best.second || (e.second == best.second && e.first < best.first)) best = e;
  if (scene.materials.empty()) return {1, 1, 1};
  if (best.first >= scene.materials.size())
    fail<InputError>("grid: material index ", best.first, " out of range (", scene.materials.size(), " materials)");
  const Material& m = scene.materials[best.first];
  Vec3 linear;
  if (m.diffuseTexture == kNoTexture || m.diffuseTexture >= scene.textures.size() ||
      scene.triangleUVs.size() != scene.triangles.size() || !textureAverage(grid, scene, cell, best.first, linear))
    return m.diffuse;
  return mul(m.diffuse, Vec3{linearToSrgb(linear.x), linearToSrgb(linear.y), linearToSrgb(linear.z)});
}

}  // namespace vox
