// Exact orientation predicates for double inputs: Shewchuk's floating-point filter inline, CGAL's exact kernel
// behind it for the close calls (exact_orient.cpp). The volume fractions decide sides with orient2d; the distance
// stage counts a line's crossings of a mesh with both.
#pragma once

#include <cmath>

#include "vox/core/math.h"

namespace vox {

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

// Sign of ((b - a) x (c - a)) . (d - a): +1 when d lies on the side of the plane (a, b, c) its normal points to, -1
// on the other, 0 in the plane. Exact for any finite doubles (CGAL's orientation_3 when the filter cannot decide).
int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

inline int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // Shewchuk's orient3d first stage, whose determinant det[a - d, b - d, c - d] has the opposite sign.
  constexpr double kEpsilon = 0x1p-53;
  constexpr double kBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
  const double adx = a.x - d.x, bdx = b.x - d.x, cdx = c.x - d.x;
  const double ady = a.y - d.y, bdy = b.y - d.y, cdy = c.y - d.y;
  const double adz = a.z - d.z, bdz = b.z - d.z, cdz = c.z - d.z;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy, cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * std::fabs(adz) +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * std::fabs(bdz) +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * std::fabs(cdz);
  if (det > kBound * permanent) return -1;
  if (-det > kBound * permanent) return 1;
  return orient3dExact(a, b, c, d);
}

}  // namespace vox
