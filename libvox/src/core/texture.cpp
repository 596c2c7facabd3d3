// Image textures of the scene model (texture.h): sampling, the sRGB transfer
// function and validation.
#include "vox/core/texture.h"

#include <algorithm>
#include <cmath>

#include "vox/core/error.h"
#include "vox/core/scene.h"

namespace vox {

namespace {

// 256 decoded values, computed once: sampling decodes four texels per lookup.
const std::array<double, 256>& srgbTable() {
  static const std::array<double, 256> table = [] {
    std::array<double, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[size_t(i)] = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    }
    return t;
  }();
  return table;
}

// A coordinate in texture units reduced to one period first (so huge
// coordinates cannot overflow an integer), then the two texel indices either
// side of it and the weight of the second.
struct Taps {
  uint32_t i0, i1;
  double f;
};

uint32_t wrapIndex(int64_t i, uint32_t n, TextureWrap mode) {
  const int64_t size = n;
  switch (mode) {
    case TextureWrap::ClampToEdge:
      return uint32_t(std::clamp<int64_t>(i, 0, size - 1));
    case TextureWrap::MirroredRepeat: {
      int64_t m = ((i % (2 * size)) + 2 * size) % (2 * size);
      return uint32_t(m < size ? m : 2 * size - 1 - m);
    }
    case TextureWrap::Repeat:
    default:
      return uint32_t(((i % size) + size) % size);
  }
}

Taps taps(double t, uint32_t n, TextureWrap mode) {
  if (!std::isfinite(t)) t = 0;
  if (mode == TextureWrap::Repeat) t -= std::floor(t);
  if (mode == TextureWrap::MirroredRepeat) t -= 2 * std::floor(t / 2);
  if (mode == TextureWrap::ClampToEdge) t = std::clamp(t, 0.0, 1.0);
  const double x = t * n - 0.5;  // texel centres sit at integers
  const double x0 = std::floor(x);
  const int64_t i = int64_t(x0);
  return {wrapIndex(i, n, mode), wrapIndex(i + 1, n, mode), x - x0};
}

}  // namespace

double srgbToLinear(uint8_t encoded) { return srgbTable()[encoded]; }

double linearToSrgb(double linear) {
  if (!(linear > 0)) return 0;  // also NaN
  if (linear >= 1) return 1;
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1 / 2.4) - 0.055;
}

Vec3 sampleTexture(const Texture& texture, TexCoord uv) {
  if (texture.width == 0 || texture.height == 0 || texture.rgb.size() != size_t(texture.width) * texture.height * 3)
    return {1, 1, 1};
  const Taps x = taps(uv.u, texture.width, texture.wrapU);
  const Taps y = taps(uv.v, texture.height, texture.wrapV);
  const auto& lut = srgbTable();
  auto texel = [&](uint32_t tx, uint32_t ty) {
    const uint8_t* p = &texture.rgb[(size_t(ty) * texture.width + tx) * 3];
    return Vec3{lut[p[0]], lut[p[1]], lut[p[2]]};
  };
  const Vec3 top = texel(x.i0, y.i0) * (1 - x.f) + texel(x.i1, y.i0) * x.f;
  const Vec3 bottom = texel(x.i0, y.i1) * (1 - x.f) + texel(x.i1, y.i1) * x.f;
  return top * (1 - y.f) + bottom * y.f;
}

void validateTextures(const Scene& scene, const std::string& source) {
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture& t = scene.textures[i];
    if (t.width == 0 || t.height == 0 || t.width > kMaxTextureSide || t.height > kMaxTextureSide)
      fail<InputError>(source, ": texture ", i, ": size ", t.width, "x", t.height, " is not between 1 and ",
                       kMaxTextureSide, " on each side");
    if (t.rgb.size() != size_t(t.width) * t.height * 3)
      fail<InputError>(source, ": texture ", i, ": ", t.rgb.size(), " bytes of texels for ", t.width, "x", t.height);
    for (TextureWrap w : {t.wrapU, t.wrapV})
      if (uint8_t(w) > uint8_t(TextureWrap::MirroredRepeat))
        fail<InputError>(source, ": texture ", i, ": unknown wrap mode ", int(w));
  }
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const uint32_t t = scene.materials[i].diffuseTexture;
    if (t != kNoTexture && t >= scene.textures.size())
      fail<InputError>(source, ": material ", i, ": texture ", t, " out of range (", scene.textures.size(),
                       " textures)");
  }
  if (!scene.triangleUVs.empty() && scene.triangleUVs.size() != scene.triangles.size())
    fail<InputError>(source, ": ", scene.triangleUVs.size(), " triangles' texture coordinates for ",
                     scene.triangles.size(), " triangles");
  for (size_t i = 0; i < scene.triangleUVs.size(); ++i)
    for (const TexCoord& c : scene.triangleUVs[i])
      if (!std::isfinite(c.u) || !std::isfinite(c.v))
        fail<InputError>(source, ": triangle ", i, ": texture coordinate is NaN or infinite");
}

}  // namespace vox
