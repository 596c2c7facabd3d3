// Whether a triangle mesh is closed: the edges that bound it (DESIGN.md "Solid fill": `--fill` decides by flood fill
// for closed surfaces and by the winding number otherwise).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "vox/core/scene.h"

namespace vox {

// Number of open edges of `triangles`: after welding vertices at exactly equal positions (a scanned mesh's triangles
// arrive as separate corners), the undirected edges that an odd number of triangles share. A closed surface, also
// a self-intersecting or non-manifold one, has none; the rim of a hole counts each of its edges once. Edges whose
// two ends weld together are skipped. Scratch memory: 48 bytes per triangle (the caller checks its budget).
uint64_t countOpenEdges(std::span<const Triangle> triangles);

// One connected piece of the oriented boundary (edges joined at welded vertices): the rim of one hole, usually.
// The oriented boundary holds the edges used more often in one direction than in the other: the open edges of a
// consistently oriented mesh, and also the seams where a mesh's orientation flips (the winding number's gradient
// comes from these edges alone).
struct OpenBoundary {
  Box bounds;         // of its edges' end points, world space
  double length = 0;  // sum of its edges' lengths, each times its direction surplus
  // Area of the cone from the centre of `bounds` over its edges: a surface inside `bounds` that closes the hole.
  double capArea = 0;
  uint64_t edges = 0;  // of them open (odd use count)
  // The triangles of that cone, oriented so that they use each boundary edge against the mesh's surplus: the mesh
  // and the caps of all its boundaries form a closed surface, whose winding number is an integer between surfaces.
  std::vector<Triangle> cap;
};
// The oriented boundary of `triangles` grouped into connected pieces. For a consistently oriented mesh the sum of
// their `edges` is countOpenEdges, which it also stores in *openEdges (one weld for both). The caps are built only
// when there are at most capLimit boundaries (up to 3 triangles of 80 bytes per mesh triangle otherwise). Same
// scratch memory, plus the caps.
std::vector<OpenBoundary> openBoundaries(std::span<const Triangle> triangles, uint64_t* openEdges = nullptr,
                                         size_t capLimit = SIZE_MAX);

// Caps are built for at most this many boundaries: more make a soup, where the caps would not pay.
inline constexpr size_t kMaxCapBoundaries = 64;
// A bound on |s|, the caps' winding number, anywhere in `region`: each cap of area A seen from a distance d adds at
// most A / (4 pi d^2), d from `region` to its boundary's box; infinity when `region` meets one. Where it stays under
// kCapBoundForInteger (< 0.5), |k - s| >= 0.5 exactly when the integer k != 0, so k alone decides.
double capWindingBound(std::span<const OpenBoundary> boundaries, const Box& region);
inline constexpr double kCapBoundForInteger = 0.45;

}  // namespace vox
