// Bridge to CGAL 5.5: Epick's orientation_2 is exact for double inputs (interval filter, then exact rationals).
#include "volume/exact_orient.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace vox::volume {

int orient2dExact(double ax, double ay, double bx, double by, double cx, double cy) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  const CGAL::Orientation o = CGAL::orientation(K::Point_2(ax, ay), K::Point_2(bx, by), K::Point_2(cx, cy));
  return o == CGAL::LEFT_TURN ? 1 : (o == CGAL::RIGHT_TURN ? -1 : 0);
}

}  // namespace vox::volume
