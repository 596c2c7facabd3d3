#include <algorithm>
#include <cmath>

#include "vox/core/solid_texture.h"

namespace vox {

double solidTextureWeight(const SolidTexture& t, const Vec3& world) {
  const Vec3 p = transformPoint(t.transform, world);
  switch (t.kind) {
    case SolidKind::Checkerboard: {
      // Parity of the sum of the floors, computed in double so that no coordinate overflows an int.
      const double sum = std::floor(p.x) + std::floor(p.y) + std::floor(p.z);
      return std::fmod(std::fabs(sum), 2.0) == 1.0 ? 0.0 : 1.0;
    }
    case SolidKind::Noise:
      return std::clamp(octaveNoise(p, t.octaves) + 0.5, 0.0, 1.0);
    case SolidKind::Marble:
      return 0.5 * (1 + std::sin(t.frequency * p.x + t.amplitude * octaveNoise(p, t.octaves)));
    case SolidKind::Wood:
      return 0.5 *
             (1 + std::sin(t.frequency * std::sqrt(p.x * p.x + p.z * p.z) + t.amplitude * octaveNoise(p, t.octaves)));
  }
  return 1;
}

const char* solidKindName(SolidKind kind) {
  switch (kind) {
    case SolidKind::Checkerboard:
      return "checkerboard";
    case SolidKind::Noise:
      return "noise";
    case SolidKind::Marble:
      return "marble";
    case SolidKind::Wood:
      return "wood";
  }
  return "unknown";
}

}  // namespace vox
