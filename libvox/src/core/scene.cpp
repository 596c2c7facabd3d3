#include "vox/core/scene.h"

#include <cfloat>

#include "vox/core/error.h"
#include "vox/core/exact_number.h"
#include "vox/core/material_at.h"

namespace vox {

Box triangleBounds(const Triangle& t) {
  return {minVec(minVec(t.v[0], t.v[1]), t.v[2]), maxVec(maxVec(t.v[0], t.v[1]), t.v[2])};
}

// The ellipsoid {M p : |p - c| <= r} has half-extent r * |row a of M's linear part| on axis a around M c.
// Rounded outward by a few ulps so the box certainly contains the ellipsoid.
Box sphereBounds(const Sphere& s) {
  const Vec3 c = transformPoint(s.transform, s.center);
  Vec3 half;
  for (int a = 0; a < 3; ++a) {
    const auto& row = s.transform.m[a];
    half.at(a) = s.radius * std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
  }
  Box box{c - half, c + half};
  if (s.isEllipsoid()) {
    for (int a = 0; a < 3; ++a) {
      const double pad = 4 * DBL_EPSILON * (std::fabs(c[a]) + half[a]);
      box.lo.at(a) -= pad;
      box.hi.at(a) += pad;
    }
  }
  return box;
}

std::optional<Box> sceneBounds(const Scene& scene) {
  std::optional<Box> out;
  auto grow = [&](const Box& b) {
    if (!out) {
      out = b;
    } else {
      out->lo = minVec(out->lo, b.lo);
      out->hi = maxVec(out->hi, b.hi);
    }
  };
  for (const auto& t : scene.triangles) grow(triangleBounds(t));
  for (const auto& s : scene.spheres) grow(sphereBounds(s));
  return out;
}

namespace {

// Materials are checked like geometry: a value that is NaN, infinite or out of range would be written into a grid
// file that the tools then refuse to read, or shade to NaN.
void validateMaterial(const Material& m, size_t i, const std::string& source) {
  const auto colour = [&](const Vec3& c, const char* what) {
    if (!isFinite(c)) fail<InputError>(source, ": material ", i, " '", m.name, "': ", what, " is NaN or infinite");
  };
  colour(m.diffuse, "diffuse colour");
  colour(m.specular, "specular colour");
  colour(m.reflective, "reflective colour");
  colour(m.transparent, "transparent colour");
  if (!std::isfinite(m.exponent) || !(m.exponent >= 0))
    fail<InputError>(source, ": material ", i, " '", m.name, "': exponent ", m.exponent,
                     " is not a finite number >= 0");
  if (!std::isfinite(m.indexOfRefraction) || !(m.indexOfRefraction > 0))
    fail<InputError>(source, ": material ", i, " '", m.name, "': index of refraction ", m.indexOfRefraction,
                     " is not a finite positive number");
}

}  // namespace

void validateScene(const Scene& scene, const std::string& source) {
  const size_t materials = scene.materials.size();
  for (size_t i = 0; i < materials; ++i) validateMaterial(scene.materials[i], i, source);
  validateSolidTextures(scene, source);
  validateTextures(scene, source);
  auto checkMaterial = [&](uint32_t m, const char* what, size_t i) {
    if (m >= materials) fail<InputError>(source, ": ", what, " ", i, ": material index ", m, " out of range");
  };
  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    const auto& t = scene.triangles[i];
    for (const auto& v : t.v)
      if (!isFinite(v)) fail<InputError>(source, ": triangle ", i, ": coordinate is NaN or infinite");
    checkMaterial(t.material, "triangle", i);
  }
  for (size_t i = 0; i < scene.spheres.size(); ++i) {
    const auto& s = scene.spheres[i];
    if (!isFinite(s.center) || !std::isfinite(s.radius))
      fail<InputError>(source, ": sphere ", i, ": centre or radius is NaN or infinite");
    if (!(s.radius > 0))
      fail<InputError>(source, ": sphere ", i, ": radius ", exactNumber(s.radius), " is not positive");
    for (const auto& row : s.transform.m)
      for (double x : row)
        if (!std::isfinite(x)) fail<InputError>(source, ": sphere ", i, ": transform is NaN or infinite");
    const auto& m = s.transform.m;
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (det == 0) fail<InputError>(source, ": sphere ", i, ": transform is singular");
    checkMaterial(s.material, "sphere", i);
  }
  for (size_t i = 0; i < scene.planes.size(); ++i) {
    const auto& p = scene.planes[i];
    if (!isFinite(p.normal) || !std::isfinite(p.offset))
      fail<InputError>(source, ": plane ", i, ": normal or offset is NaN or infinite");
    if (length(p.normal) == 0) fail<InputError>(source, ": plane ", i, ": normal is zero");
    checkMaterial(p.material, "plane", i);
  }
  for (const auto& l : scene.lights)
    if (!isFinite(l.direction) || !isFinite(l.position) || !isFinite(l.color))
      fail<InputError>(source, ": light is NaN or infinite");
  if (scene.camera) validateCamera(*scene.camera, source);
}

void validateCamera(const Camera& c, const std::string& source) {
  if (!isFinite(c.center) || !isFinite(c.direction) || !isFinite(c.up) || !std::isfinite(c.fovDegrees) ||
      !std::isfinite(c.orthoHeight))
    fail<InputError>(source, ": camera is NaN or infinite");
  // The image frame (DESIGN.md camera convention) needs a direction and an up that span a plane.
  if (!(length(c.direction) > 0)) fail<InputError>(source, ": camera direction is zero");
  if (!(length(cross(normalize(c.direction), c.up)) > 0))
    fail<InputError>(source, ": camera up is zero or parallel to its direction");
  if (c.kind == CameraKind::Perspective && !(c.fovDegrees > 0 && c.fovDegrees < 180))
    fail<InputError>(source, ": camera field of view ", exactNumber(c.fovDegrees), " is not between 0 and 180 degrees");
  if (c.kind == CameraKind::Orthographic && !(c.orthoHeight > 0))
    fail<InputError>(source, ": orthographic camera size ", exactNumber(c.orthoHeight), " is not positive");
}

Camera defaultCamera(const Box& bounds) {
  const Vec3 centre = (bounds.lo + bounds.hi) * 0.5;
  const Vec3 extent = bounds.hi - bounds.lo;
  double radius = 0.5 * length(extent);
  if (!(radius > 0)) radius = 1;
  Camera cam;
  cam.kind = CameraKind::Perspective;
  cam.fovDegrees = 40;
  const double distance = radius / std::sin(cam.fovDegrees * M_PI / 360.0);
  cam.center = centre + Vec3{0, 0, distance};
  cam.direction = {0, 0, -1};
  cam.up = {0, 1, 0};
  return cam;
}

}  // namespace vox
