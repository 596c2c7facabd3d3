// The scene model: only what scenes require (DESIGN.md "Scene model"). All geometry in world space, double precision.
// Primitive ids, used by grids and grid files, number triangles first, then spheres, then planes:
//   id in [0, T) -> triangles[id], [T, T+S) -> spheres[id - T], [T+S, T+S+P) -> planes[id - T - S].
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vox/core/huge_pages.h"
#include "vox/core/math.h"
#include "vox/core/solid_texture.h"
#include "vox/core/texture.h"

namespace vox {

struct Material {
  std::string name;
  Vec3 diffuse{1, 1, 1};
  Vec3 specular{0, 0, 0};
  double exponent = 1;
  Vec3 reflective{0, 0, 0};
  Vec3 transparent{0, 0, 0};
  double indexOfRefraction = 1;
  // A solid texture (Scene::solidTextures index) that replaces the fields above by a blend of two other materials
  // at each point; kNoSolidTexture for a plain Phong material.
  uint32_t solidTexture = kNoSolidTexture;
  // An image texture (Scene::textures index) whose colour `diffuse` multiplies (glTF baseColorTexture, OBJ
  // map_Kd), over the triangles' Scene::triangleUVs; kNoTexture for none.
  uint32_t diffuseTexture = kNoTexture;
};

struct Triangle {
  std::array<Vec3, 3> v;
  uint32_t material = 0;
};

// A sphere of `center` and `radius` mapped by `transform` (object to world). Similarity transforms are folded into
// center and radius by the importers, so `transform` is the identity unless the sphere is really an ellipsoid.
struct Sphere {
  Vec3 center;
  double radius = 1;
  Mat4 transform;
  uint32_t material = 0;

  bool isEllipsoid() const { return !transform.isIdentity(); }
};

// The infinite plane dot(normal, p) = offset; `normal` has unit length.
struct Plane {
  Vec3 normal{0, 1, 0};
  double offset = 0;
  uint32_t material = 0;
};

enum class CameraKind : uint8_t { Perspective = 0, Orthographic = 1 };

// Which side of the image a camera's angle (perspective) or size (orthographic) spans.
enum class CameraSpan : uint8_t {
  Height = 0,      // DESIGN.md's convention: vox-trace's flags, glTF cameras, defaultCamera
  LongerSide = 1,  // the course's cameras: the width of a wide image, the height of a square or tall one
};

// `direction` and `up` need not be unit length or orthogonal; renderers orthonormalise them as DESIGN.md says.
struct Camera {
  CameraKind kind = CameraKind::Perspective;
  Vec3 center{0, 0, 5};
  Vec3 direction{0, 0, -1};
  Vec3 up{0, 1, 0};
  double fovDegrees = 45;  // perspective: field of view across the side `span` names (vertical by default)
  double orthoHeight = 2;  // orthographic: world extent of the image plane across that side (the course's `size`)
  CameraSpan span = CameraSpan::Height;
};

enum class LightKind : uint8_t { Directional = 0, Point = 1 };

struct Light {
  LightKind kind = LightKind::Directional;
  Vec3 direction{0, -1, 0};  // directional: the direction light travels
  Vec3 position{0, 0, 0};    // point
  Vec3 color{1, 1, 1};
  Vec3 attenuation{1, 0, 0};  // point: constant, linear, quadratic
};

struct Scene {
  std::vector<Material> materials;          // never empty after import: importers add a default white material
  std::vector<SolidTexture> solidTextures;  // referenced by Material::solidTexture
  HugeVector<Triangle> triangles;           // large ones on whole huge pages (a mesh is read into it once)
  std::vector<Sphere> spheres;
  std::vector<Plane> planes;
  std::vector<Texture> textures;                     // referenced by Material::diffuseTexture
  std::vector<std::array<TexCoord, 3>> triangleUVs;  // empty (no texture coordinates), or one per triangle
  std::optional<Camera> camera;                      // none: tools frame the bounds (defaultCamera)
  std::vector<Light> lights;                         // empty: tools add a headlight
  Vec3 background{0.5, 0.5, 0.5};
  Vec3 ambient{0, 0, 0};
  std::vector<std::string> warnings;  // importer remarks for the tools to print (the library never prints)

  size_t primitiveCount() const { return triangles.size() + spheres.size() + planes.size(); }
  size_t boundedCount() const { return triangles.size() + spheres.size(); }
};

// World-space bounds of a triangle, and of a sphere or ellipsoid (exact extents of the ellipsoid, rounded outward).
Box triangleBounds(const Triangle& t);
Box sphereBounds(const Sphere& s);
// Bounds of all bounded primitives; nullopt when there is none.
std::optional<Box> sceneBounds(const Scene& scene);
// A triangle whose vertices are collinear or coincide (zero area).
bool isDegenerate(const Triangle& t);
// Throws InputError naming `source` when any coordinate, radius or matrix entry is NaN or infinite, a radius is
// not positive, a material index is out of range, or a material holds a NaN or infinite colour, an exponent that is
// not a finite number >= 0, or an index of refraction that is not a finite positive number.
void validateScene(const Scene& scene, const std::string& source);
// Throws InputError naming `source` when the camera cannot form an image: non-finite values, a zero direction, an
// up that is zero or parallel to the direction, a field of view outside (0, 180) degrees, a size that is not
// positive. Part of validateScene.
void validateCamera(const Camera& camera, const std::string& source);
// A perspective camera looking at the centre of `bounds` from +z, framing it; used when a scene has none.
Camera defaultCamera(const Box& bounds);

}  // namespace vox
