// The Textures section of grid files (docs/grid-format.md "Sections"): image
// textures, which material uses which, and per-triangle texture coordinates, so
// that vox-export colours voxels from the grid file alone.
//
// Body: u64 T, then T textures (string name, u32 width, u32 height, u8 wrapU,
// u8 wrapV, u64 width*height*3, then as many bytes of sRGB texels, rows from
// the top); u64 M, then M pairs (u32 material, u32 texture), materials
// ascending; u64 N (0 or the triangle count), then N triangles' texture
// coordinates (u0 v0 u1 v1 u2 v2 as doubles, bit for bit).
#include <string>

#include "io/grid_sections.h"

namespace vox {

bool hasTexturesSection(const Scene& scene, const Grid&) { return !scene.textures.empty(); }

void putTexturesSection(ByteWriter& w, const Scene& scene, const Grid&, std::string&) {
  w.put(uint64_t(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    w.putString(t.name);
    w.put(t.width);
    w.put(t.height);
    w.put(uint8_t(t.wrapU));
    w.put(uint8_t(t.wrapV));
    w.putArray(t.rgb);
  }
  uint64_t textured = 0;
  for (const Material& m : scene.materials) textured += m.diffuseTexture != kNoTexture;
  w.put(textured);
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (scene.materials[i].diffuseTexture != kNoTexture) {
      w.put(uint32_t(i));
      w.put(scene.materials[i].diffuseTexture);
    }
  w.put(uint64_t(scene.triangleUVs.size()));
  for (const auto& uv : scene.triangleUVs)
    for (const TexCoord& c : uv) {
      w.put(c.u);
      w.put(c.v);
    }
}

namespace {

TextureWrap getWrap(ByteReader& r) {
  const uint8_t w = r.get<uint8_t>();
  if (w > uint8_t(TextureWrap::MirroredRepeat)) r.corrupt("unknown texture wrap mode " + std::to_string(w));
  return TextureWrap(w);
}

Texture getTexture(ByteReader& r) {
  Texture t;
  t.name = r.getString();
  t.width = r.get<uint32_t>();
  t.height = r.get<uint32_t>();
  if (t.width == 0 || t.height == 0 || t.width > kMaxTextureSide || t.height > kMaxTextureSide)
    r.corrupt("texture size " + std::to_string(t.width) + "x" + std::to_string(t.height) + " out of range");
  t.wrapU = getWrap(r);
  t.wrapV = getWrap(r);
  const size_t at = r.position();
  t.rgb = r.getArray<uint8_t>("texel byte");  // its count is checked against the file before allocating
  if (t.rgb.size() != uint64_t(t.width) * t.height * 3)
    fail<InputError>(r.name(), ": byte ", at, ": ", t.rgb.size(), " texel bytes for a ", t.width, "x", t.height,
                     " texture");
  return t;
}

}  // namespace

void getTexturesSection(ByteReader& r, Scene& scene, Grid&, const SectionContext&) {
  const uint64_t nTextures = r.getCount(4 + 4 + 4 + 2 + 8 + 3, "texture");
  if (nTextures == 0) r.corrupt("textures section without textures");
  scene.textures.reserve(nTextures);
  for (uint64_t i = 0; i < nTextures; ++i) scene.textures.push_back(getTexture(r));
  const uint64_t nTextured = r.getCount(8, "textured material");
  uint64_t previous = 0;
  for (uint64_t k = 0; k < nTextured; ++k) {
    const uint32_t m = r.get<uint32_t>();
    const uint32_t t = r.get<uint32_t>();
    if (m >= scene.materials.size() || (k > 0 && m <= previous))
      r.corrupt("textured material " + std::to_string(m) + " out of range or out of order");
    if (t >= nTextures) r.corrupt("material texture " + std::to_string(t) + " out of range");
    scene.materials[m].diffuseTexture = t;
    previous = m;
  }
  const uint64_t nUV = r.getCount(6 * 8, "texture coordinate");
  if (nUV != 0 && nUV != scene.triangles.size())
    r.corrupt(std::to_string(nUV) + " triangles' texture coordinates for " + std::to_string(scene.triangles.size()) +
              " triangles");
  scene.triangleUVs.resize(nUV);
  for (auto& uv : scene.triangleUVs)
    for (TexCoord& c : uv) {
      c.u = r.getFinite("texture coordinate");
      c.v = r.getFinite("texture coordinate");
    }
}

}  // namespace vox
