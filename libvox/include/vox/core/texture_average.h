// The average colour of an image texture over the part of a triangle inside a
// cell, weighted by world-space area. In core so that the exporters' cell
// colours (export/cell_color.cpp) and the renderer can both reach it.
#pragma once

#include <array>

#include "vox/core/math.h"
#include "vox/core/texture.h"

namespace vox {

// Sums of texture colours in linear light. `area` collects colour times world
// area of the covered parts; `touch` collects one sample per triangle that
// meets the box in no area (an edge or corner contact, a degenerate triangle),
// used only when no triangle covers any area.
struct TextureSum {
  Vec3 area;
  double areaWeight = 0;
  Vec3 touch;
  double touchCount = 0;

  // The average in linear light. Precondition: !empty().
  bool empty() const { return areaWeight == 0 && touchCount == 0; }
  Vec3 average() const { return areaWeight > 0 ? area / areaWeight : touch / touchCount; }
};

// Adds `texture` over the part of triangle `t` (texture coordinates `uv`)
// inside the closed box `box`: the clipped polygon is split into a fan, and
// each piece is split into n x n equal triangles, each sampled (bilinearly) at
// its centroid, with n growing with the texels the piece covers (1 to 32) so
// that coarse cells average over the texels they cover, not a few of them
// (beyond 1024 texels a piece, at stratified pseudo-random points: noise, not
// aliasing). Never throws.
void addTextureOverBox(const Texture& texture, const std::array<Vec3, 3>& t, const std::array<TexCoord, 3>& uv,
                       const Box& box, TextureSum& sum);

}  // namespace vox
