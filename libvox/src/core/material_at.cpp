#include "vox/core/material_at.h"

#include <vector>

#include "vox/core/error.h"

namespace vox {
namespace {

// The Phong fields only: the name is not copied (a string copy per ray hit would allocate for long names).
Material phongOf(const Material& a) {
  Material m;
  m.diffuse = a.diffuse;
  m.specular = a.specular;
  m.exponent = a.exponent;
  m.reflective = a.reflective;
  m.transparent = a.transparent;
  m.indexOfRefraction = a.indexOfRefraction;
  return m;
}

Material blend(const Material& a, const Material& b, double v) {
  const double w = 1 - v;
  Material m;
  m.diffuse = a.diffuse * v + b.diffuse * w;
  m.specular = a.specular * v + b.specular * w;
  m.exponent = a.exponent * v + b.exponent * w;
  m.reflective = a.reflective * v + b.reflective * w;
  m.transparent = a.transparent * v + b.transparent * w;
  m.indexOfRefraction = a.indexOfRefraction * v + b.indexOfRefraction * w;
  return m;
}

Material resolve(const Scene& scene, uint32_t id, const Vec3& p, uint32_t depth) {
  const Material& m = scene.materials[id];
  if (m.solidTexture == kNoSolidTexture || depth > kMaxSolidNesting) return phongOf(m);
  const SolidTexture& t = scene.solidTextures[m.solidTexture];
  const double v = solidTextureWeight(t, p);
  // A checkerboard square needs only one of its materials, and noise weights of exactly 0 or 1 likewise.
  if (v == 1) return resolve(scene, t.materials[0], p, depth + 1);
  if (v == 0) return resolve(scene, t.materials[1], p, depth + 1);
  return blend(resolve(scene, t.materials[0], p, depth + 1), resolve(scene, t.materials[1], p, depth + 1), v);
}

// Depth of the texture chain below material id: 0 for a plain material. `state` marks materials being visited (1)
// and finished (2, with their depth in `depth`), so a cycle is found and shared sub-materials are walked once.
uint32_t nestingOf(const Scene& scene, uint32_t id, std::vector<uint8_t>& state, std::vector<uint32_t>& depth,
                   uint32_t level, const std::string& source) {
  if (state[id] == 2) return depth[id];
  if (state[id] == 1) fail<InputError>(source, ": material ", id, ": solid textures form a cycle");
  const Material& m = scene.materials[id];
  uint32_t d = 0;
  if (m.solidTexture != kNoSolidTexture) {
    if (level >= kMaxSolidNesting)
      fail<InputError>(source, ": material ", id, ": solid textures nested deeper than ", kMaxSolidNesting);
    state[id] = 1;
    const SolidTexture& t = scene.solidTextures[m.solidTexture];
    for (uint32_t sub : t.materials) d = std::max(d, 1 + nestingOf(scene, sub, state, depth, level + 1, source));
    if (d > kMaxSolidNesting)
      fail<InputError>(source, ": material ", id, ": solid textures nested deeper than ", kMaxSolidNesting);
  }
  state[id] = 2;
  depth[id] = d;
  return d;
}

void validateTexture(const SolidTexture& t, size_t i, size_t materials, const std::string& source) {
  if (t.kind != SolidKind::Checkerboard && t.kind != SolidKind::Noise && t.kind != SolidKind::Marble &&
      t.kind != SolidKind::Wood)
    fail<InputError>(source, ": solid texture ", i, ": unknown kind ", int(t.kind));
  for (uint32_t sub : t.materials)
    if (sub >= materials) fail<InputError>(source, ": solid texture ", i, ": material index ", sub, " out of range");
  for (const auto& row : t.transform.m)
    for (double x : row)
      if (!std::isfinite(x)) fail<InputError>(source, ": solid texture ", i, ": transform is NaN or infinite");
  if (!std::isfinite(t.frequency) || !std::isfinite(t.amplitude))
    fail<InputError>(source, ": solid texture ", i, ": frequency or amplitude is NaN or infinite");
  if (t.octaves > kMaxOctaves)
    fail<InputError>(source, ": solid texture ", i, ": ", t.octaves, " octaves (at most ", kMaxOctaves, ")");
}

}  // namespace

Material materialAt(const Scene& scene, uint32_t id, const Vec3& p) { return resolve(scene, id, p, 0); }

void validateSolidTextures(const Scene& scene, const std::string& source) {
  for (size_t i = 0; i < scene.solidTextures.size(); ++i)
    validateTexture(scene.solidTextures[i], i, scene.materials.size(), source);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const uint32_t t = scene.materials[i].solidTexture;
    if (t != kNoSolidTexture && t >= scene.solidTextures.size())
      fail<InputError>(source, ": material ", i, ": solid texture ", t, " out of range");
  }
  std::vector<uint8_t> state(scene.materials.size(), 0);
  std::vector<uint32_t> depth(scene.materials.size(), 0);
  for (uint32_t i = 0; i < scene.materials.size(); ++i) nestingOf(scene, i, state, depth, 0, source);
}

}  // namespace vox
