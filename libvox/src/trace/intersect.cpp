// Ray-primitive tests. Kept out of line on purpose: one compiled copy serves every caller, so no call site can get
// a differently contracted or reassociated version of the arithmetic (see intersect.h).
#include "vox/trace/intersect.h"

#include <cmath>

#include "trace/triangle_kernel.h"

namespace vox {

TriangleData prepareTriangle(const Triangle& t) {
  const Vec3 e1 = t.v[1] - t.v[0], e2 = t.v[2] - t.v[0];
  return {t.v[0], e1, e2, cross(e1, e2)};
}

SphereData prepareSphere(const Sphere& s) {
  SphereData d;
  d.center = s.center;
  d.radius = s.radius;
  d.ellipsoid = s.isEllipsoid();
  if (d.ellipsoid) {
    d.worldToObject = inverse(s.transform);
    d.normalToWorld = transpose(d.worldToObject);
  }
  return d;
}

// The arithmetic lives in triangle_kernel.h, shared with the packet test.
bool intersectTriangle(const TriangleData& tri, const Ray& ray, double& t) {
  const Vec3& o = ray.origin;
  const Vec3& d = ray.direction;
  const double v0[3] = {tri.v0.x, tri.v0.y, tri.v0.z}, e1[3] = {tri.e1.x, tri.e1.y, tri.e1.z},
               e2[3] = {tri.e2.x, tri.e2.y, tri.e2.z}, n[3] = {tri.n.x, tri.n.y, tri.n.z};
  double hitT;
  if (!kernel::triangleHit(v0, e1, e2, n, o.x, o.y, o.z, d.x, d.y, d.z, ray.tMin, ray.tMax, hitT)) return false;
  t = hitT;
  return true;
}

bool intersectSphere(const SphereData& sphere, const Ray& ray, double& t) {
  Vec3 o = ray.origin;
  Vec3 d = ray.direction;
  if (sphere.ellipsoid) {
    o = transformPoint(sphere.worldToObject, o);
    d = transformVector(sphere.worldToObject, d);
  }
  const double a = dot(d, d);
  if (!(a > 0) || !std::isfinite(a)) return false;
  const Vec3 oc = o - sphere.center;
  const double b = dot(oc, d);
  // Squared distance of the centre from the line, from the perpendicular vector rather than |oc|^2 - b^2/a, which
  // cancels badly for distant origins (Haines et al., Ray Tracing Gems, ch. 7).
  const Vec3 perp = oc - d * (b / a);
  const double r2 = sphere.radius * sphere.radius;
  const double h2 = r2 - dot(perp, perp);
  if (!(h2 >= 0)) return false;
  const double s = std::sqrt(a * h2);
  const double c = dot(oc, oc) - r2;
  // Stable roots: q/a and c/q, with q of the same sign as -b.
  const double q = -(b + std::copysign(s, b));
  double t0, t1;
  if (q == 0) {
    t0 = t1 = 0;
  } else {
    t0 = q / a;
    t1 = c / q;
  }
  if (t0 > t1) std::swap(t0, t1);
  if (t0 >= ray.tMin && t0 <= ray.tMax) {
    t = t0;
    return true;
  }
  if (t1 >= ray.tMin && t1 <= ray.tMax) {
    t = t1;
    return true;
  }
  return false;
}

bool intersectPlane(const Plane& plane, const Ray& ray, double& t) {
  const double denom = dot(plane.normal, ray.direction);
  if (denom == 0 || !std::isfinite(denom)) return false;
  const double hitT = (plane.offset - dot(plane.normal, ray.origin)) / denom;
  if (!(hitT >= ray.tMin && hitT <= ray.tMax)) return false;
  t = hitT;
  return true;
}

Vec3 triangleNormal(const TriangleData& tri) { return normalize(cross(tri.e1, tri.e2)); }

Vec3 sphereNormal(const SphereData& sphere, const Ray& ray, double t) {
  if (!sphere.ellipsoid) return normalize(ray.origin + ray.direction * t - sphere.center);
  const Vec3 o = transformPoint(sphere.worldToObject, ray.origin);
  const Vec3 d = transformVector(sphere.worldToObject, ray.direction);
  const Vec3 objectNormal = o + d * t - sphere.center;
  return normalize(transformVector(sphere.normalToWorld, objectNormal));
}

}  // namespace vox
