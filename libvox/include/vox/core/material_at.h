// Materials that vary in space: the Phong parameters of a scene material at a world point, through its solid
// texture (solid_texture.h) when it has one.
#pragma once

#include <string>

#include "vox/core/scene.h"

namespace vox {

// The plain Phong material that scene.materials[id] is at world point p: itself when it has no solid texture,
// else v * first + (1 - v) * second of its texture (solid_texture.h), each evaluated at p in turn; every colour,
// the exponent and the index of refraction blended linearly. The name is left empty (no allocation per call).
// Preconditions: validateSolidTextures passed (indices in range, nesting bounded).
Material materialAt(const Scene& scene, uint32_t id, const Vec3& p);

// Throws InputError naming `source` when a material names a solid texture that does not exist, a texture names a
// material out of range, the textures form a cycle or nest deeper than kMaxSolidNesting, a transform, frequency or
// amplitude is not finite, octaves exceed kMaxOctaves, or a texture kind is unknown.
void validateSolidTextures(const Scene& scene, const std::string& source);

}  // namespace vox
