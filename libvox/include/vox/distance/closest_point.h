// Closest points on the bounded primitives (DESIGN.md "Distance and volume"): triangles, spheres and ellipsoids.
// World space, double precision; the error bound against the exact closest distance is in docs/distance.md and
// tested against CGAL's exact kernel (tests/distance_test.cpp).
#pragma once

#include <array>

#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

// The point of triangle (a, b, c) nearest to p (Ericson, "Real-Time Collision Detection", 5.1.5: the Voronoi region
// of p decided by the signs of barycentric sub-areas). A degenerate triangle (a segment or a point) is handled as
// its longest edge, so the result is always a point of the triangle and never NaN for finite input.
Vec3 closestPointOnTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);
// The squared distance from p to the triangle, computed relative to p (more accurate than from the point above when
// the coordinates are large against the distance).
double squaredDistanceToTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p);

// What a lower bound of the distance from any point to one triangle needs, computed once per triangle: the unit
// normal, and the unit normals of the three edges in the triangle's plane, pointing out (edge a->b, b->c, c->a).
// The distance from p is at least that to the plane joined with the edge it lies farthest outside of (the triangle
// lies in the half-plane inside each edge); that bound is the distance itself except in a vertex's region.
struct TriangleLowerBound {
  Vec3 normal;
  std::array<Vec3, 3> edgeNormals;
  double slack = 0;     // the bound's rounding, per unit of |p - a|_1: a multiple of the normal's conditioning
  double slackAt0 = 0;  // ... and its part from the triangle's own size
  bool usable = false;  // false for a degenerate or needle triangle, whose normal rounding cannot bound: no pruning
};
TriangleLowerBound triangleLowerBound(const Triangle& t);

// squaredDistanceToTriangle when it can be at most bound2; +infinity, without computing it, when the lower bound
// above, made smaller by its rounding error and by the distance's own, is farther: so rounding never skips a
// triangle whose computed distance is within the bound. The band and the nearest-primitive search prune with it.
double squaredDistanceToTriangleWithin(const Triangle& t, const TriangleLowerBound& bound, const Vec3& p,
                                       double bound2);

// The point of segment [a, b] nearest to p.
Vec3 closestPointOnSegment(const Vec3& a, const Vec3& b, const Vec3& p);

// A sphere or an ellipsoid in its principal frame: surface points are center + sum_i axes[i] * semi[i] * u_i with
// |u| = 1; axes orthonormal, semi > 0 descending (Eberly's e0 >= e1 >= e2).
struct EllipsoidShape {
  Vec3 center;
  std::array<Vec3, 3> axes{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  Vec3 semi{1, 1, 1};
  bool isSphere = true;  // all semi-axes equal: the closed form applies
};

// The eigenvectors of the symmetric matrix m (cyclic Jacobi rotations to convergence): orthonormal to rounding.
std::array<Vec3, 3> symmetricEigenvectors(const std::array<std::array<double, 3>, 3>& m);

// The principal frame of a scene sphere: the sphere itself, or the ellipsoid its transform makes (the eigenvectors
// of L L^T, L the transform's linear part, by cyclic Jacobi rotations to convergence). Throws InputError for a
// singular transform.
EllipsoidShape ellipsoidShape(const Sphere& sphere);

// The point of the shape's surface nearest to p. Spheres in closed form; ellipsoids by Eberly's method ("Distance
// from a Point to an Ellipse, an Ellipsoid, or a Hyperellipsoid", 2013): the root of a monotone function found by
// bisection to the last bit, so the result is accurate to a few ulps of the semi-axes (docs/distance.md).
Vec3 closestPointOnEllipsoid(const EllipsoidShape& shape, const Vec3& p);

// The axis-aligned box around the shape (a cube of its longest semi-axis about its centre).
Box ellipsoidBounds(const EllipsoidShape& shape);

// Whether p lies strictly inside the shape (sum (u_i / semi_i)^2 < 1 in the principal frame).
bool insideEllipsoid(const EllipsoidShape& shape, const Vec3& p);

}  // namespace vox
