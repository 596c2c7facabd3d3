// Image textures of the scene model: decoded colour images (glTF
// baseColorTexture, OBJ map_Kd) and the texture coordinates that map triangles
// onto them. Plain data and the few free functions every stage shares
// (sampling, the sRGB transfer function, validation); decoding lives in the
// importers, averaging over cells in export/.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vox/core/math.h"

namespace vox {

struct Scene;

// A texture coordinate: (0, 0) is the top-left corner of the texture's row 0, u grows to the right, v downwards
// (glTF's convention). Texel (x, y) covers [x, x+1] / width by [y, y+1] / height; its centre is at
// ((x + 0.5) / width, (y + 0.5) / height). OBJ's vt, whose v grows upwards, is kept as written: the OBJ importer
// stores its images' rows bottom-up instead.
struct TexCoord {
  double u = 0;
  double v = 0;
};

// How coordinates outside [0, 1] map into the image (glTF sampler wrapS /
// wrapT; OBJ `-clamp on` is ClampToEdge).
enum class TextureWrap : uint8_t { Repeat = 0, ClampToEdge = 1, MirroredRepeat = 2 };

// Largest width or height accepted anywhere (import and grid files): 16384 is
// the largest texture GPUs take, and keeps width * height * 3 far from
// overflow.
inline constexpr uint32_t kMaxTextureSide = 16384;

// Material::diffuseTexture of a material without an image texture.
inline constexpr uint32_t kNoTexture = UINT32_MAX;

// A decoded colour image: `rgb` holds width * height texels, 3 bytes each (R, G, B), row by row from row 0 (the
// image's top for glTF, its bottom for OBJ), sRGB-encoded as the file stores them (alpha is dropped: colours are
// averaged over covered area, not blended).
struct Texture {
  std::string name;  // where it came from (image uri or file), for messages and vox-info
  uint32_t width = 0;
  uint32_t height = 0;
  TextureWrap wrapU = TextureWrap::Repeat;
  TextureWrap wrapV = TextureWrap::Repeat;
  std::vector<uint8_t> rgb;
};

// The sRGB transfer function (IEC 61966-2-1): 8-bit encoded value to linear
// light in [0, 1], and linear light (clamped to [0, 1]) back to an encoded
// value in [0, 1].
double srgbToLinear(uint8_t encoded);
double linearToSrgb(double linear);

// The texture's colour at `uv` in linear light, bilinear between the four
// nearest texel centres, each coordinate wrapped by its mode. Precondition: a
// valid texture (validateTextures). Never throws.
Vec3 sampleTexture(const Texture& texture, TexCoord uv);

// Throws InputError naming `source` when a texture is empty, larger than
// kMaxTextureSide on a side, or its `rgb` size is not width * height * 3, a
// wrap mode is unknown, a material's diffuseTexture is neither kNoTexture nor a
// texture index, triangleUVs is neither empty nor one entry per triangle, or a
// texture coordinate is not finite. Part of validateScene.
void validateTextures(const Scene& scene, const std::string& source);

}  // namespace vox
