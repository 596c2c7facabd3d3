#include "vox/core/power_of_two_frame.h"

#include <algorithm>
#include <cfloat>
#include <charconv>

#include "vox/core/error.h"

namespace vox {

namespace {

// The shortest decimal that reads back as x: a limit and the value it refuses never print as the same number.
std::string shortest(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

const double kMaxCoordinate = std::ldexp(1.0, kMaxCoordinateExponent);

void checkCoordinate(double x, const char* which, const std::string& what) {
  if (std::fabs(x) > kMaxCoordinate)
    fail<InputError>(what, ": ", which, " coordinate ", shortest(x), " is beyond +-", shortest(kMaxCoordinate), " (2^",
                     kMaxCoordinateExponent, "), the range of distances and volume fractions");
}

}  // namespace

double magnitude(const Box& b) {
  double m = 0;
  for (int a = 0; a < 3; ++a) m = std::max({m, std::fabs(b.lo[a]), std::fabs(b.hi[a])});
  return m;
}

PowerOfTwoFrame frameForMagnitude(double magnitude) {
  if (!(magnitude > 0) || !std::isfinite(magnitude)) return {};
  return {std::ilogb(magnitude)};
}

PowerOfTwoFrame sceneFrame(const Scene& scene) {
  const std::optional<Box> b = sceneBounds(scene);
  return b ? frameForMagnitude(magnitude(*b)) : PowerOfTwoFrame{};
}

PowerOfTwoFrame fractionFrame(const Scene& scene, const Box& bounds) {
  const std::optional<Box> b = sceneBounds(scene);
  return frameForMagnitude(std::max(magnitude(bounds), b ? magnitude(*b) : 0.0));
}

Scene sceneInFrame(const Scene& scene, const PowerOfTwoFrame& frame) {
  Scene out;
  out.triangles.resize(scene.triangles.size());
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    out.triangles[t].material = scene.triangles[t].material;
    for (int v = 0; v < 3; ++v) out.triangles[t].v[v] = frame.toFrame(scene.triangles[t].v[v]);
  }
  out.spheres = scene.spheres;
  for (Sphere& s : out.spheres) {
    if (s.isEllipsoid()) {  // world = transform * object: scaling the world scales the transform's three rows
      for (int r = 0; r < 3; ++r)
        for (double& x : s.transform.m[r]) x = frame.toFrame(x);
    } else {
      s.center = frame.toFrame(s.center);
      s.radius = frame.toFrame(s.radius);
    }
  }
  out.planes = scene.planes;
  for (Plane& p : out.planes) p.offset = frame.toFrame(p.offset);
  return out;
}

void checkNumericDomain(const Scene& scene, const Box& bounds, const std::array<uint32_t, 3>& dims,
                        const PowerOfTwoFrame& frame, bool checkReach, const std::string& what) {
  if (const std::optional<Box> b = sceneBounds(scene))
    for (int a = 0; a < 3; ++a)
      checkCoordinate(std::fabs(b->lo[a]) > std::fabs(b->hi[a]) ? b->lo[a] : b->hi[a], "the scene's", what);
  for (int a = 0; a < 3; ++a) {
    checkCoordinate(bounds.lo[a], "the bounds'", what);
    checkCoordinate(bounds.hi[a], "the bounds'", what);
  }
  // Distances are measured from cell centres (the outermost ones are the first and last of each axis): a single
  // cell of 1e300 about a unit scene has its centre on the scene, and is answered.
  double centres = 0;
  for (int a = 0; a < 3; ++a)
    centres = std::max({centres, std::fabs(cellCentreOnAxis(bounds, dims, a, 0)),
                        std::fabs(cellCentreOnAxis(bounds, dims, a, dims[a] - 1))});
  if (checkReach && frame.toFrame(centres) > std::ldexp(1.0, kFrameReachExponent))
    fail<InputError>(what, ": cell centres reach ", shortest(centres), " (bounds ", shortest(magnitude(bounds)),
                     "), more than 2^", kFrameReachExponent, " times the scene's magnitude 2^", frame.exponent,
                     ": distances are computed within +-",
                     shortest(frame.toWorld(std::ldexp(1.0, kFrameReachExponent))), " for this scene");
  for (int a = 0; a < 3; ++a) {
    const double edge = (bounds.hi[a] - bounds.lo[a]) / dims[a];
    if (!(edge >= DBL_MIN))
      fail<InputError>(what, ": cell edge ", shortest(edge), " on axis ", "xyz"[a],
                       " is below the smallest normal double ", shortest(DBL_MIN),
                       ": distances and volume fractions need cells at least that wide");
    for (uint32_t i = 0; i < dims[a]; ++i)
      if (!(cellBoundary(bounds, dims, a, i) < cellBoundary(bounds, dims, a, i + 1)))
        fail<InputError>(what, ": cells of ", shortest(edge), " on axis ", "xyz"[a], " are narrower than the spacing ",
                         shortest(std::nextafter(std::fabs(cellBoundary(bounds, dims, a, i)), INFINITY) -
                                  std::fabs(cellBoundary(bounds, dims, a, i))),
                         " of doubles at ", shortest(cellBoundary(bounds, dims, a, i)), ": cell boundaries ", i,
                         " and ", i + 1, " coincide; use fewer cells or move the scene nearer the origin");
  }
}

void checkPointsInDomain(std::span<const double> points, const PowerOfTwoFrame& frame) {
  const double reach = std::min(kMaxCoordinate, frame.toWorld(std::ldexp(1.0, kFrameReachExponent)));
  for (size_t i = 0; i < points.size(); ++i)
    if (std::fabs(points[i]) > reach)
      fail<InputError>("points[", i / 3, ", ", i % 3, "] is ", shortest(points[i]),
                       ": distances to this scene are computed for coordinates within +-", shortest(reach), " (2^",
                       reach == kMaxCoordinate ? kMaxCoordinateExponent : kFrameReachExponent + frame.exponent, ")");
}

}  // namespace vox
