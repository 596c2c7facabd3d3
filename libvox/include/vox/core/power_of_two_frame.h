// The frame distances, signs and volume fractions are computed in (docs/limits.md "Numeric domain"): the scene and
// the grid bounds scaled by 2^-e, e chosen from their magnitude so that it lies in [1, 2). Scaling by a power of two
// is exact in binary floating point (no rounding, short of overflow and underflow), so every operation in the frame
// sees the same numbers whatever the scene's scale: a scene's answers at scale 2^k equal its answers at scale 1
// times 2^k, bit for bit, and no square, cube or product of coordinates overflows or underflows at 1e300 or 1e-300.
#pragma once

#include <cmath>
#include <span>
#include <string>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/scene.h"

namespace vox {

// Coordinates (scene, bounds, query points) of distances and fractions lie within +-2^kMaxCoordinateExponent, so
// that a distance across the grid (at most 2 sqrt(3) times the largest coordinate) never overflows.
inline constexpr int kMaxCoordinateExponent = 1020;
// Query points and cell centres lie within +-2^kFrameReachExponent in the scene's frame (the scene's magnitude in
// [1, 2)), so that squared distances never overflow (2^1000 < 2^1024).
inline constexpr int kFrameReachExponent = 500;

struct PowerOfTwoFrame {
  int exponent = 0;  // world = frame * 2^exponent

  double toFrame(double x) const { return std::ldexp(x, -exponent); }
  double toWorld(double x) const { return std::ldexp(x, exponent); }
  Vec3 toFrame(const Vec3& v) const { return {toFrame(v.x), toFrame(v.y), toFrame(v.z)}; }
  Vec3 toWorld(const Vec3& v) const { return {toWorld(v.x), toWorld(v.y), toWorld(v.z)}; }
  Box toFrame(const Box& b) const { return {toFrame(b.lo), toFrame(b.hi)}; }
  bool identity() const { return exponent == 0; }
  bool operator==(const PowerOfTwoFrame&) const = default;
};

// The largest |coordinate| of a box.
double magnitude(const Box& b);
// The frame in which `magnitude` lies in [1, 2): exponent ilogb(magnitude); the identity for 0.
PowerOfTwoFrame frameForMagnitude(double magnitude);
// The frame of distances and signs: from the scene's bounded primitives alone (so that a grid or a query point far
// from the scene does not shrink the scene to nothing); the identity for a scene without any.
PowerOfTwoFrame sceneFrame(const Scene& scene);

// The frame of volume fractions: from the scene and the grid's bounds together (the cells' volumes are what must
// neither overflow nor underflow).
PowerOfTwoFrame fractionFrame(const Scene& scene, const Box& bounds);

// The geometry of `scene` (triangles, spheres and ellipsoids, planes) scaled into `frame`; no materials, textures,
// cameras or lights. An ellipsoid's transform is scaled (its object-space centre and radius kept), a sphere's
// centre and radius.
Scene sceneInFrame(const Scene& scene, const PowerOfTwoFrame& frame);

// The grid's bounds scaled into `frame` for the span of a computation on the caller's grid (its cells and runs
// unchanged), and back to world units whatever happens: the band and the fill.
class FramedBounds {
 public:
  FramedBounds(Grid& grid, const PowerOfTwoFrame& frame) : grid_(grid), world_(grid.bounds) {
    grid.bounds = frame.toFrame(world_);
  }
  ~FramedBounds() { grid_.bounds = world_; }
  FramedBounds(const FramedBounds&) = delete;
  FramedBounds& operator=(const FramedBounds&) = delete;

 private:
  Grid& grid_;
  Box world_;
};

// Throws InputError, one line prefixed by `what`, when the grid cannot give exact-or-bounded distances, signs or
// fractions in `frame`: a coordinate of the scene or the bounds beyond +-2^kMaxCoordinateExponent; cell centres
// beyond +-2^kFrameReachExponent in the frame (`checkReach`); a cell edge below the smallest normal double (cell
// boundaries would round unevenly); cell boundaries b(i) = lo + (hi - lo) * i / n that are not strictly increasing
// (cells narrower than the coordinates' spacing: a unit cube moved to 1e16). Each message gives the allowed range.
void checkNumericDomain(const Scene& scene, const Box& bounds, const std::array<uint32_t, 3>& dims,
                        const PowerOfTwoFrame& frame, bool checkReach, const std::string& what);

// Throws InputError naming points[i, axis] when a point's coordinate is beyond +-2^kMaxCoordinateExponent or, in
// `frame`, beyond +-2^kFrameReachExponent (its squared distance could overflow).
void checkPointsInDomain(std::span<const double> points, const PowerOfTwoFrame& frame);

}  // namespace vox
