// Bridge to CGAL 5.5: Epick's orientation_2 and orientation_3 are exact for double inputs (interval filter, then
// exact rationals).
#include "vox/core/exact_orient.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace vox {

int orient2dExact(double ax, double ay, double bx, double by, double cx, double cy) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  const CGAL::Orientation o = CGAL::orientation(K::Point_2(ax, ay), K::Point_2(bx, by), K::Point_2(cx, cy));
  return o == CGAL::LEFT_TURN ? 1 : (o == CGAL::RIGHT_TURN ? -1 : 0);
}

int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  const CGAL::Orientation o = CGAL::orientation(K::Point_3(a.x, a.y, a.z), K::Point_3(b.x, b.y, b.z),
                                                K::Point_3(c.x, c.y, c.z), K::Point_3(d.x, d.y, d.z));
  return o == CGAL::POSITIVE ? 1 : (o == CGAL::NEGATIVE ? -1 : 0);
}

}  // namespace vox
