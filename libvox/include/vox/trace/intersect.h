// Ray-primitive intersection in double precision. Every routine is deterministic and compiled once (intersect.cpp),
// so the grid walk and the brute-force loop get bit-identical t for the same ray and primitive, which is what makes
// `--accel grid` and `--accel none` images identical.
#pragma once

#include "vox/core/math.h"
#include "vox/trace/ray.h"
#include "vox/core/scene.h"

namespace vox {

// A triangle prepared for the ray test: first vertex, the two edges from it and their (unnormalized) cross product
// n = e1 x e2. World space.
struct TriangleData {
  Vec3 v0, e1, e2, n;
};
TriangleData prepareTriangle(const Triangle& t);

// A sphere or ellipsoid prepared for tracing: object-space centre and radius, and for an ellipsoid the inverse of
// Sphere::transform (world to object) and its transpose (object normals to world normals).
struct SphereData {
  Vec3 center;
  double radius = 1;
  bool ellipsoid = false;
  Mat4 worldToObject;
  Mat4 normalToWorld;
};
// Throws vox::Error when an ellipsoid's transform is singular.
SphereData prepareSphere(const Sphere& s);

// Each test returns true and sets `t` when the ray meets the surface at a parameter in [ray.tMin, ray.tMax]
// (the nearest such parameter). Boundaries are closed: edges and vertices of a triangle count as hits.
// Degenerate triangles and rays parallel to a plane hit nothing. `t` is left unchanged on a miss.
bool intersectTriangle(const TriangleData& tri, const Ray& ray, double& t);
// Ellipsoids: the ray is mapped into object space by worldToObject (an affine map keeps the ray parameter), solved
// against the object-space sphere there.
bool intersectSphere(const SphereData& sphere, const Ray& ray, double& t);
bool intersectPlane(const Plane& plane, const Ray& ray, double& t);

// Unit geometric normals at a hit, world space, not flipped towards the viewer.
Vec3 triangleNormal(const TriangleData& tri);
Vec3 sphereNormal(const SphereData& sphere, const Ray& ray, double t);
inline Vec3 planeNormal(const Plane& plane) { return normalize(plane.normal); }

}  // namespace vox
