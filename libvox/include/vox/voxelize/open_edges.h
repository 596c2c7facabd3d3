// Whether a triangle mesh is closed: the edges that bound it (DESIGN.md "Solid fill": `--fill` decides by flood fill
// for closed surfaces and by the winding number otherwise).
#pragma once

#include <cstdint>
#include <span>

#include "vox/core/scene.h"

namespace vox {

// Number of open edges of `triangles`: after welding vertices at exactly equal positions (a scanned mesh's triangles
// arrive as separate corners), the undirected edges that an odd number of triangles share. A closed surface, also
// a self-intersecting or non-manifold one, has none; the rim of a hole counts each of its edges once. Edges whose
// two ends weld together are skipped. Scratch memory: 48 bytes per triangle (the caller checks its budget).
uint64_t countOpenEdges(std::span<const Triangle> triangles);

}  // namespace vox
