// The colour of a voxel for `--color material`, shared by every exporter
// (meshes and voxel formats) so that a cell has one colour in every file.
#pragma once

#include <cstddef>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

// Display colour (sRGB-encoded components in [0, 1], as written to 8-bit files)
// of occupied cell `cell` (an index into grid.cellKeys, not a key):
//  - the material held by most of the cell's primitives is chosen (ties: the
//  lowest material index);
//  - without an image texture (or without scene.triangleUVs) the colour is its
//  `diffuse`, as it always was;
//  - with one, the texture is averaged in linear light over the parts of that
//  material's triangles inside the
//    closed cell, weighted by world-space area (texture_average.h), encoded to
//    sRGB and multiplied by `diffuse` (so a white texture gives exactly the
//    untextured colour; for a glTF factor of 1 the texture's own colour).
//    Triangles that touch the cell without area count only when no triangle
//    covers any; spheres and planes of a textured material, which have no
//    texture coordinates, are not sampled.
// A cell without primitives gets kSolidCellColor, a scene without materials
// white. Throws InputError when a primitive id or material index is out of
// range (grids decoded from files are checked before; this guards the rest).
// Reads only; safe to call from many threads at once.
Vec3 cellMaterialColor(const Grid& grid, const Scene& scene, size_t cell);

}  // namespace vox
