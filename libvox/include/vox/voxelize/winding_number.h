// Generalized winding number of a triangle mesh (Jacobson, Kavan and Sorkine-Hornung 2013, "Robust inside-outside
// segmentation using generalized winding numbers"): the sum of the signed solid angles of the triangles seen from a
// point, over 4 pi. It is 1 inside and 0 outside a closed, outward-oriented surface (-1 inside an inward-oriented
// one), and degrades smoothly where the surface has holes or overlaps; `--fill` calls a point inside when its
// magnitude is at least 0.5 (fill.h). Fast evaluation after Barill, Dickson, Schmidt, Levin and Jacobson 2018, "Fast
// winding numbers for soups and clouds": a bounding-volume tree whose far nodes are replaced by a dipole expansion.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

// Solid angle of triangle (a, b, c) seen from q over 4 pi, signed: positive when q sees the triangle's back, i.e.
// when q lies on the side opposite to the normal (b - a) x (c - a) (van Oosterom and Strackee 1983). 0 for a
// degenerate triangle and for q in the triangle's plane outside it. World space, any finite coordinates.
double triangleWindingNumber(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q);

// Exact (up to rounding) winding number of `triangles` at q: the sum over every triangle. O(triangles); the
// reference for tests and the fallback for tiny meshes.
double windingNumberExact(std::span<const Triangle> triangles, const Vec3& q);

// The tree of Barill et al.: nodes in depth-first order (node 0 the root; a node's first child follows it, `skip`
// is the index just past its subtree), triangles reordered so that each node owns a contiguous range.
struct WindingTree {
  struct Node {
    Vec3 center;                    // area-weighted centroid of the node's triangles: the expansion point
    double radius = 0;              // largest distance from center to a vertex of the node's triangles
    Vec3 normalSum;                 // sum of area-weighted normals (order 1 term)
    double moment[9] = {};          // sum of area * normal (x) (centroid - center), row-major (order 2 term)
    uint32_t first = 0, count = 0;  // triangle range in `corners`
    uint32_t skip = 0;              // next node after this subtree; a leaf is skip == own index + 1
  };
  std::vector<Node> nodes;
  std::vector<std::array<Vec3, 3>> corners;  // triangles in tree order
};

// Builds the tree over `triangles` (world space). Memory: about 300 bytes per triangle. Throws nothing.
WindingTree buildWindingTree(std::span<const Triangle> triangles);

// Winding number at q: a node whose expansion point lies farther than `beta` times its radius from q contributes
// its second-order expansion, every other leaf its exact triangles. beta = 2 errs by about 1e-3 on scanned meshes
// (Barill et al. Fig. 11; our tests bound it against windingNumberExact); a larger beta is slower and closer.
double windingNumber(const WindingTree& tree, const Vec3& q, double beta = 2);

// The winding number at q, close enough to decide |offset - w| >= threshold as the exact value does: the fast value
// (beta 2, about 1e-3 off), recomputed with beta 8 where |offset - w| lies within 0.05 of the threshold. The fill
// decides with it (offset 0 for the mesh, k for the holes' caps), and so do the distances' signs.
double windingNumberToDecide(const WindingTree& tree, const Vec3& q, double offset, double threshold);

}  // namespace vox
