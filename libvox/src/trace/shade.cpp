#include "trace/shade.h"

#include <algorithm>

namespace vox {

uint32_t primitiveMaterial(const Scene& scene, const Accel& accel, uint32_t prim) {
  if (prim < accel.triangleCount) return scene.triangles[prim].material;
  prim -= accel.triangleCount;
  if (prim < accel.sphereCount) return scene.spheres[prim].material;
  return scene.planes[prim - accel.sphereCount].material;
}

Vec3 hitNormal(const Accel& accel, const Ray& ray, const Hit& hit) {
  uint32_t prim = hit.prim;
  if (prim < accel.triangleCount) return triangleNormal(accel.triangles[prim]);
  prim -= accel.triangleCount;
  if (prim < accel.sphereCount) return sphereNormal(accel.spheres[prim], ray, hit.t);
  return planeNormal(accel.planes[prim - accel.sphereCount]);
}

Surface Shader::surface(const Ray& ray, const Hit& hit) const {
  Surface s;
  s.p = ray.origin + ray.direction * hit.t;
  const Vec3 n = hitNormal(accel, ray, hit);
  s.backFace = dot(n, ray.direction) > 0;
  s.n = s.backFace ? -n : n;
  const uint32_t id =
      std::min<uint32_t>(primitiveMaterial(scene, accel, hit.prim), uint32_t(scene.materials.size() - 1));
  s.mat = materialAt(scene, id, s.p);
  // Rays leave the surface from a hair off it, relative to the scene and to the magnitude of p.
  const double pMag = std::max({std::fabs(s.p.x), std::fabs(s.p.y), std::fabs(s.p.z)});
  s.eps = 1e-7 * sceneSize + 64 * std::numeric_limits<double>::epsilon() * pMag;
  return s;
}

namespace {

double largest(const Vec3& c) { return std::max({c.x, c.y, c.z}); }

}  // namespace

Vec3 Shader::secondary(const Ray& ray, const Surface& s, uint32_t depth, double weight, TraceStats& st) const {
  if (depth >= options.bounces) return {};
  Vec3 color;
  const Vec3 d = normalize(ray.direction);
  // A ray leaving on the side of s.n starts above the surface, one going through starts below it.
  const auto leave = [&](const Vec3& dir, bool through) {
    Ray r;
    r.origin = s.p + s.n * (through ? -s.eps : s.eps);
    r.direction = dir;
    r.tMin = s.eps;
    return r;
  };
  const double wr = weight * largest(s.mat.reflective);
  if (wr > 0 && wr >= options.weight)
    color = color + mul(s.mat.reflective, trace(leave(reflectDirection(d, s.n), false), depth + 1, wr, st));
  const double wt = weight * largest(s.mat.transparent);
  if (wt > 0 && wt >= options.weight) {
    // Entering when the ray meets the front of the surface (the side its normal points to), leaving otherwise;
    // outside is air (index 1), as in the course.
    const double eta = s.backFace ? s.mat.indexOfRefraction : 1 / s.mat.indexOfRefraction;
    const std::optional<Vec3> t = refractDirection(d, s.n, eta);
    // Beyond the critical angle all of the transmitted light is reflected (total internal reflection).
    const Ray next = t ? leave(*t, true) : leave(reflectDirection(d, s.n), false);
    color = color + mul(s.mat.transparent, trace(next, depth + 1, wt, st));
  }
  return color;
}

Vec3 Shader::trace(const Ray& ray, uint32_t depth, double weight, TraceStats& st) const {
  const Hit hit = traceRay(accel, ray, &st);
  if (!hit.valid()) return scene.background;
  const Surface s = surface(ray, hit);
  const Vec3 c = local(ray, s, [&](size_t, const Ray& shadow) { return !occluded(accel, shadow, &st); });
  return c + secondary(ray, s, depth, weight, st);
}

}  // namespace vox
