// The `exact` method. Bridge to CGAL 5.5: Epick's predicates are exact for double inputs (filtered, with an exact
// fallback), which is all we need since cell boundaries and vertices are doubles. Trap 4 of DEBIAN-NOTES: CGAL sets
// -frounding-math; this file must never be built with -ffast-math.
//
// CGAL's Triangle_3/Iso_cuboid_3 do_intersect goes through the triangle's supporting plane, which is undefined for a
// degenerate triangle, so collinear and coincident vertices are sent to the segment and point predicates instead.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/FPU.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/intersections.h>

#include <optional>

#include "voxelize/sphere_overlap.h"
#include "vox/voxelize/overlap.h"

namespace vox {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

Point toPoint(const Vec3& v) { return {v.x, v.y, v.z}; }
K::Iso_cuboid_3 toCuboid(const Box& b) { return {toPoint(b.lo), toPoint(b.hi)}; }

}  // namespace

bool isDegenerate(const Triangle& t) { return CGAL::collinear(toPoint(t.v[0]), toPoint(t.v[1]), toPoint(t.v[2])); }

bool triangleBoxExact(const Triangle& t, const Box& box) {
  const Point p[3] = {toPoint(t.v[0]), toPoint(t.v[1]), toPoint(t.v[2])};
  const K::Iso_cuboid_3 cuboid = toCuboid(box);
  if (!CGAL::collinear(p[0], p[1], p[2])) return CGAL::do_intersect(K::Triangle_3(p[0], p[1], p[2]), cuboid);
  // Collinear: the triangle is the segment between its lexicographically smallest and largest vertex.
  const auto [lo, hi] = std::minmax(
      {p[0], p[1], p[2]}, [](const Point& a, const Point& b) { return CGAL::compare_xyz(a, b) == CGAL::SMALLER; });
  if (lo == hi) return !cuboid.has_on_unbounded_side(lo);
  return CGAL::do_intersect(K::Segment_3(lo, hi), cuboid);
}

// The interval stage shared by `exact` and `sat`: CGAL's own filtering technique. nullopt when an interval
// comparison is uncertain (CGAL throws Uncertain_conversion_exception for it).
namespace {
std::optional<bool> sphereBoxInterval(const Sphere& s, const Box& box) {
  CGAL::Protect_FPU_rounding<true> guard;
  try {
    return sphereSurfaceMeetsBox<CGAL::Interval_nt<false>>(s, box);
  } catch (const CGAL::Uncertain_conversion_exception&) {
    return std::nullopt;
  }
}
}  // namespace

// Exact rationals only when the intervals cannot decide.
bool sphereBoxFiltered(const Sphere& s, const Box& box, bool* usedFallback) {
  const std::optional<bool> decided = sphereBoxInterval(s, box);
  if (usedFallback) *usedFallback = !decided;
  return decided ? *decided : sphereSurfaceMeetsBox<CGAL::Gmpq>(s, box);
}

bool sphereBoxExact(const Sphere& s, const Box& box) { return sphereBoxFiltered(s, box, nullptr); }

// `sat` for spheres: the interval stage alone; where intervals cannot decide, the cell is taken.
bool sphereBoxSat(const Sphere& s, const Box& box) { return sphereBoxInterval(s, box).value_or(true); }

}  // namespace vox
