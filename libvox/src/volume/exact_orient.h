// The one exact predicate the volume fractions need: the orientation of three points of the plane, with Shewchuk's
// floating-point filter inline and CGAL's exact kernel behind it for the close calls (exact_orient.cpp).
#pragma once

#include <cmath>

namespace vox::volume {

// Sign of (b - a) x (c - a): +1 when a, b, c turn counter-clockwise, -1 clockwise, 0 collinear. Exact for any
// finite doubles. CGAL's Epick is called only when the filter cannot decide.
int orient2dExact(double ax, double ay, double bx, double by, double cx, double cy);

inline int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  // Shewchuk 1997, "Adaptive precision floating-point arithmetic and fast robust geometric predicates", orient2d's
  // first stage: the rounded determinant's sign is right when its magnitude exceeds ccwerrboundA times detsum.
  constexpr double kEpsilon = 0x1p-53;
  constexpr double kBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
  const double detLeft = (ax - cx) * (by - cy);
  const double detRight = (ay - cy) * (bx - cx);
  const double det = detLeft - detRight;
  if (det > kBound * (std::fabs(detLeft) + std::fabs(detRight))) return 1;
  if (-det > kBound * (std::fabs(detLeft) + std::fabs(detRight))) return -1;
  return orient2dExact(ax, ay, bx, by, cx, cy);
}

}  // namespace vox::volume
