// Rays and hits of the tracer. World space, double precision.
#pragma once

#include <cstdint>
#include <limits>

#include "vox/core/math.h"

namespace vox {

inline constexpr uint32_t kNoPrim = 0xffffffffu;
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The points origin + t * direction for t in [tMin, tMax]. `direction` need not have unit length; t is measured in
// multiples of it. Components of +-0 and denormal size are allowed; all-zero or non-finite directions hit nothing.
struct Ray {
  Vec3 origin;
  Vec3 direction{0, 0, -1};
  double tMin = 0;
  double tMax = kInfinity;
};

// The nearest hit of a ray: ray parameter t and primitive id (scene.h numbering); prim == kNoPrim when nothing is
// hit. Ties in t go to the smaller primitive id, on every code path.
struct Hit {
  double t = kInfinity;
  uint32_t prim = kNoPrim;

  bool valid() const { return prim != kNoPrim; }
};

// The order in which hits are preferred: nearer first, then smaller id. Used by every path so that grid and brute
// force traversal pick the same hit.
inline bool closer(double t, uint32_t prim, const Hit& best) { return t < best.t || (t == best.t && prim < best.prim); }

}  // namespace vox
