// The shade mode's lighting model, the course's (MIT 6.837 F04, assignments 3, 4 and 6; docs/trace.md "Shading"):
// ambient * diffuse + per visible light (diffuse * n.l + specular * (n.h)^exponent) * light colour, plus
// reflectiveColor * (the colour seen along the mirror direction) and transparentColor * (the colour seen along the
// refracted direction), recursively. Internal to render.cpp and its tests.
#pragma once

#include <limits>
#include <optional>
#include <vector>

#include "vox/core/material_at.h"
#include "vox/trace/accel.h"
#include "vox/trace/render.h"
#include "vox/trace/traverse.h"

namespace vox {

// Mirror direction of unit direction d about unit normal n (either side).
inline Vec3 reflectDirection(const Vec3& d, const Vec3& n) { return d - n * (2 * dot(d, n)); }

// Refracted direction of unit direction d entering the medium on the far side of unit normal n, where n faces the
// incoming ray (dot(d, n) < 0) and eta = (index on d's side) / (index beyond). Snell's law in vector form;
// nullopt beyond the critical angle (total internal reflection).
inline std::optional<Vec3> refractDirection(const Vec3& d, const Vec3& n, double eta) {
  const double cosI = -dot(d, n);
  const double k = 1 - eta * eta * (1 - cosI * cosI);
  if (k < 0) return std::nullopt;
  return normalize(d * eta + n * (eta * cosI - std::sqrt(k)));
}

// The material index of primitive `prim` and its unit geometric normal at the hit (not turned to the viewer).
uint32_t primitiveMaterial(const Scene& scene, const Accel& accel, uint32_t prim);
Vec3 hitNormal(const Accel& accel, const Ray& ray, const Hit& hit);

// Direction towards a light (unit), distance to it (infinite for directional) and the attenuated colour.
struct LightSample {
  Vec3 toLight;
  double distance;
  Vec3 color;
};
inline LightSample sampleLight(const Light& light, const Vec3& p) {
  if (light.kind == LightKind::Directional) return {normalize(-light.direction), kInfinity, light.color};
  const Vec3 d = light.position - p;
  const double dist = length(d);
  const double att = light.attenuation.x + light.attenuation.y * dist + light.attenuation.z * dist * dist;
  return {dist > 0 ? d / dist : Vec3{0, 0, 1}, dist, att > 0 ? light.color / att : light.color};
}

// What a hit needs for shading: the point, the geometric normal turned to face the ray, whether the ray met the
// back of the surface (the side the primitive's normal points away from), and the material there.
struct Surface {
  Vec3 p;
  Vec3 n;         // unit, dot(n, ray.direction) <= 0
  bool backFace;  // the primitive's own normal pointed along the ray
  Material mat;
  double eps;  // offset of rays leaving the surface
};

struct Shader {
  const Scene& scene;
  const Accel& accel;
  const RenderOptions& options;
  std::vector<Light> lights;
  bool castShadows = true;  // false for the headlight, or --no-shadows
  double sceneSize = 1;

  Surface surface(const Ray& ray, const Hit& hit) const;

  // The local part: ambient, diffuse and Blinn-Phong specular of every light that `visible(light index, shadow
  // ray)` says is seen (asked only for lights in front of the surface, and only when shadows are cast). A back
  // face without shadeBack is black, as in the course.
  template <typename Visible>
  Vec3 local(const Ray& ray, const Surface& s, Visible&& visible) const {
    if (s.backFace && !options.shadeBack) return {};
    const Vec3 view = normalize(-ray.direction);
    Vec3 color = mul(scene.ambient, s.mat.diffuse);
    for (size_t li = 0; li < lights.size(); ++li) {
      const LightSample ls = sampleLight(lights[li], s.p);
      const double nl = dot(s.n, ls.toLight);
      if (nl <= 0) continue;
      if (castShadows) {
        Ray shadow;
        shadow.origin = s.p + s.n * s.eps;
        shadow.direction = ls.toLight;
        shadow.tMin = s.eps;
        shadow.tMax = ls.distance - s.eps;
        if (shadow.tMax > shadow.tMin && !visible(li, shadow)) continue;
      }
      Vec3 c = s.mat.diffuse * nl;
      if (s.mat.specular.x > 0 || s.mat.specular.y > 0 || s.mat.specular.z > 0) {
        const double nh = dot(s.n, normalize(ls.toLight + view));
        if (nh > 0) c = c + s.mat.specular * std::pow(nh, s.mat.exponent);
      }
      color = color + mul(c, ls.color);
    }
    return color;
  }

  // The reflected and refracted light at a surface hit by `ray` at recursion depth `depth` (0 for a primary ray)
  // whose path weight so far is `weight`; the rays are traced with traceRay, shadows with occluded.
  Vec3 secondary(const Ray& ray, const Surface& s, uint32_t depth, double weight, TraceStats& st) const;
  // The full colour along a ray at recursion depth `depth`: background when nothing is hit.
  Vec3 trace(const Ray& ray, uint32_t depth, double weight, TraceStats& st) const;
};

}  // namespace vox
