// The part of a triangle inside an axis-aligned box, as a convex polygon whose
// vertices carry their barycentric coordinates in the triangle (so any
// per-vertex attribute, such as texture coordinates, follows the clip).
#pragma once

#include <array>
#include <cstddef>

#include "vox/core/math.h"

namespace vox {

struct ClipVertex {
  Vec3 p;     // world space
  Vec3 bary;  // weights of the triangle's vertices 0, 1, 2 (sum 1)
};

// A triangle clipped by six planes has at most 3 + 6 vertices.
struct ClipPolygon {
  std::array<ClipVertex, 9> v;
  size_t size = 0;
};

// Sutherland-Hodgman (1974) clip of triangle `t` to the closed box `box`, plane
// by plane, in floating point. The result is empty, or a convex polygon
// (possibly of zero area when the triangle only touches the box). Never throws.
ClipPolygon clipTriangleToBox(const std::array<Vec3, 3>& t, const Box& box);

// Barycentric coordinates of the point of triangle `t` nearest to `p` (Ericson,
// Real-Time Collision Detection, 5.1.5); for a degenerate triangle, of one of
// its nearest vertices or edge points.
Vec3 nearestBarycentric(const std::array<Vec3, 3>& t, const Vec3& p);

}  // namespace vox
