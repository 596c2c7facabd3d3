// The SolidTextures section of grid files (docs/grid-format.md "Sections"): the course's Checkerboard, Noise,
// Marble and Wood materials (solid_texture.h), so that vox-trace renders them from the grid file alone.
//
// Body: u64 S, then S textures (u8 kind 1..4, 16 doubles of the world-to-texture transform row by row, u32 first
// material, u32 second material, u32 octaves, double frequency, double amplitude); u64 M, then M pairs
// (u32 material, u32 texture), materials ascending. Every index, kind and number is checked, and the materials'
// texture graph must be acyclic and at most kMaxSolidNesting deep (validateSolidTextures).
#include <string>

#include "io/grid_sections.h"
#include "vox/core/material_at.h"

namespace vox {

namespace {
constexpr size_t kTextureBytes = 1 + 16 * 8 + 4 + 4 + 4 + 8 + 8;
}

bool hasSolidTexturesSection(const Scene& scene, const Grid&) { return !scene.solidTextures.empty(); }

void putSolidTexturesSection(ByteWriter& w, const Scene& scene, const Grid&, std::string&) {
  w.put(uint64_t(scene.solidTextures.size()));
  for (const SolidTexture& t : scene.solidTextures) {
    w.put(uint8_t(t.kind));
    for (const auto& row : t.transform.m)
      for (double x : row) w.put(x);
    w.put(t.materials[0]);
    w.put(t.materials[1]);
    w.put(t.octaves);
    w.put(t.frequency);
    w.put(t.amplitude);
  }
  uint64_t textured = 0;
  for (const Material& m : scene.materials) textured += m.solidTexture != kNoSolidTexture;
  w.put(textured);
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (scene.materials[i].solidTexture != kNoSolidTexture) {
      w.put(uint32_t(i));
      w.put(scene.materials[i].solidTexture);
    }
}

namespace {

SolidTexture getSolidTexture(ByteReader& r, size_t materials) {
  SolidTexture t;
  const uint8_t kind = r.get<uint8_t>();
  if (kind < uint8_t(SolidKind::Checkerboard) || kind > uint8_t(SolidKind::Wood))
    r.corrupt("unknown solid texture kind " + std::to_string(kind));
  t.kind = SolidKind(kind);
  for (auto& row : t.transform.m)
    for (double& x : row) x = r.getFinite("solid texture transform");
  for (uint32_t& m : t.materials) {
    m = r.get<uint32_t>();
    if (m >= materials) r.corrupt("solid texture material " + std::to_string(m) + " out of range");
  }
  t.octaves = r.get<uint32_t>();
  if (t.octaves > kMaxOctaves) r.corrupt("solid texture octaves " + std::to_string(t.octaves) + " out of range");
  t.frequency = r.getFinite("solid texture frequency");
  t.amplitude = r.getFinite("solid texture amplitude");
  return t;
}

}  // namespace

void getSolidTexturesSection(ByteReader& r, Scene& scene, Grid&, const SectionContext&) {
  const uint64_t n = r.getCount(kTextureBytes, "solid texture");
  if (n == 0) r.corrupt("solid textures section without textures");
  scene.solidTextures.reserve(n);
  for (uint64_t i = 0; i < n; ++i) scene.solidTextures.push_back(getSolidTexture(r, scene.materials.size()));
  const uint64_t nTextured = r.getCount(8, "solid-textured material");
  uint64_t previous = 0;
  for (uint64_t k = 0; k < nTextured; ++k) {
    const uint32_t m = r.get<uint32_t>();
    const uint32_t t = r.get<uint32_t>();
    if (m >= scene.materials.size() || (k > 0 && m <= previous))
      r.corrupt("solid-textured material " + std::to_string(m) + " out of range or out of order");
    if (t >= n) r.corrupt("material solid texture " + std::to_string(t) + " out of range");
    scene.materials[m].solidTexture = t;
    previous = m;
  }
  // Cycles and nesting depth concern the whole graph, so they are checked once it is read.
  validateSolidTextures(scene, r.name() + ": byte " + std::to_string(r.position()));
}

}  // namespace vox
