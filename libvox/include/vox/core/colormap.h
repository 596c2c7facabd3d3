// The colour maps: for primitive counts, shared by `vox-trace --mode voxels` and `vox-export --color count` so that a
// cell has the same colour in the image and in the exported mesh, and the heat map of `vox-trace --mode count`.
// In core because the renderer and the exporters both use them and neither may include the other.
#pragma once

#include <cstdint>

#include "vox/core/math.h"

namespace vox {

// Maps the number of primitives in a cell to a display colour (components in [0, 1], sRGB-encoded as written to
// 8-bit files) on matplotlib's viridis ramp: dark violet for 1 primitive, yellow for `maxCount`. The position on the
// ramp is logarithmic, t = ln(count) / ln(maxCount), because counts are heavy-tailed (most cells hold one to three
// primitives, a few hold hundreds) and a linear ramp would paint almost every cell the same violet.
// count <= 1 or maxCount <= 1 gives the start of the ramp; count >= maxCount its end. Never throws.
Vec3 countColor(uint32_t count, uint32_t maxCount);

// viridis at t in [0, 1] (clamped), piecewise linear through nine samples of matplotlib's table.
Vec3 viridis(double t);

// Heat colour of value / maxValue in [0, 1] (dark blue, through red, to white) for the count mode.
Vec3 heatColor(double value, double maxValue);

}  // namespace vox
