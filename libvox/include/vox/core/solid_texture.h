// Solid textures of the course's text format (MIT 6.837 F04, assignment 6): Checkerboard, Noise, Marble and Wood.
// Each one maps a world point into texture space by its own transform and there chooses between, or blends, two
// other materials of the scene (which may be solid textures themselves). Definitions (docs/trace.md "Solid
// textures"), with p the texture-space point and N the octave sum of Perlin's improved noise:
//   N(p)         = sum_{i < octaves} perlinNoise(2^i p) / 2^i
//   Checkerboard: the second material where floor(p.x) + floor(p.y) + floor(p.z) is odd, else the first
//   Noise:        v = clamp(N(p) + 0.5, 0, 1)
//   Marble:       v = (1 + sin(frequency * p.x + amplitude * N(p))) / 2
//   Wood:         v = (1 + sin(frequency * sqrt(p.x^2 + p.z^2) + amplitude * N(p))) / 2   (rings around y)
//   and the material is v * first + (1 - v) * second, every Phong parameter blended linearly.
#pragma once

#include <cstdint>

#include "vox/core/math.h"

namespace vox {

enum class SolidKind : uint8_t { Checkerboard = 1, Noise = 2, Marble = 3, Wood = 4 };

inline constexpr uint32_t kNoSolidTexture = 0xffffffffu;
// Solid textures may nest (a Checkerboard of two Woods in scene6_18); deeper chains are refused on import and in
// grid files, so that evaluating a material is bounded.
inline constexpr uint32_t kMaxSolidNesting = 16;
inline constexpr uint32_t kMaxOctaves = 32;

struct SolidTexture {
  SolidKind kind = SolidKind::Checkerboard;
  Mat4 transform;                       // world point -> texture space
  uint32_t materials[2] = {0, 0};       // indices into Scene::materials
  uint32_t octaves = 0;                 // Noise, Marble, Wood
  double frequency = 1, amplitude = 1;  // Marble, Wood
};

// Ken Perlin's improved noise (SIGGRAPH 2002, his reference implementation's permutation and gradients), in
// [-1, 1], zero at integer lattice points.
double perlinNoise(double x, double y, double z);
// sum_{i < octaves} perlinNoise(2^i p) / 2^i.
double octaveNoise(const Vec3& p, uint32_t octaves);
// The weight v of the texture's first material at world point p (see above); Checkerboard gives 1 or 0.
double solidTextureWeight(const SolidTexture& t, const Vec3& world);

// A short name for messages and vox-info: "checkerboard", "noise", "marble", "wood"; "unknown" otherwise.
const char* solidKindName(SolidKind kind);

}  // namespace vox
