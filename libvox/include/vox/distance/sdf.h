// Signed distance fields (DESIGN.md "Distance and volume"): the narrow band of `--sdf`, and the inside test that signs
// it. Distances are Euclidean, in world units, to the nearest point of any bounded primitive (triangles, spheres,
// ellipsoids; planes are left out); negative inside the solid as `--fill` decides it. The sign never scales the
// magnitude. Error bound against the exact distance: docs/distance.md.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/core/scene.h"
#include "vox/distance/closest_point.h"
#include "vox/voxelize/open_edges.h"
#include "vox/voxelize/voxelize.h"
#include "vox/voxelize/winding_number.h"

namespace vox {

// Largest half-width accepted, in smallest cell edges: a wider band is a dense field (libvox.sdf), whose size the
// caller plans; this bound keeps a typo (--sdf 3000) from asking for terabytes.
inline constexpr double kMaxSdfHalfWidth = 64;

struct SdfOptions {
  double halfWidth = 3;                     // in smallest cell edges (OpenVDB's default band)
  uint64_t memoryLimitBytes = 16ull << 30;  // scratch beyond this throws LimitError
  // Called with a fraction in [0, 1], possibly from worker threads; return false to cancel (throws vox::Error).
  std::function<bool(double)> progress;
};

struct SdfBand {
  std::vector<uint64_t> keys;  // sorted cell keys
  std::vector<double> values;  // signed distance at each cell's centre
};

// Which side of the solid a point is on: inside a sphere or an ellipsoid, or where the triangles' generalized
// winding number w has magnitude >= kWindingThreshold (the fill's rule, fill.h). Every signed distance asks it (the
// band, libvox.sdf, Grid.distance), so their signs agree bit for bit. Decided exactly, without evaluating w where
// it can: the mesh closed by the caps of its holes (openBoundaries) has an integer winding number k, and w = k - s,
// s the caps'. k at p is the signed count of the crossings of p's row line (along x) before p, each decided exactly
// (orient2d against the triangle's edges with the line perturbed symbolically, so an edge or a vertex on the line
// counts once; orient3d against its plane); the triangles whose (y, z) box holds the line come from a tree. Far
// from every hole (capWindingBound < kCapBoundForInteger) k alone decides; nearer, s comes from the caps' tree, and
// where |k - s| is within 0.25 of the threshold it is summed over the caps' triangles (exact to rounding there: the
// decision is w's unless |w| is within about 1e-12 of the threshold or the tree errs by 0.25); a point on a cap
// takes w summed over every triangle. A closed, consistently oriented mesh has no caps: exact. More
// than kMaxCapBoundaries holes (a soup) fall back to the winding tree (windingNumberToDecide, about 1e-3 off).
class InsideTest {
 public:
  // The test views the scene's triangles without copying them (a copy was 80 bytes a triangle at the peak of
  // --sdf's memory): `scene` must outlive it.
  explicit InsideTest(const Scene& scene);
  // The same over the scene scaled into `frame` (vox/core/power_of_two_frame.h): `inside` then takes points in
  // that frame, where winding numbers of a scene at 1e-300 or 1e300 neither underflow nor overflow. The test keeps
  // the scaled triangles itself (shared by its copies): `scene` need not outlive it.
  InsideTest(const Scene& scene, const PowerOfTwoFrame& frame);
  bool inside(const Vec3& p) const;
  const PowerOfTwoFrame& frame() const { return frame_; }

  // A crossing of a row line with a triangle (index into the test's triangles: the mesh's, then the caps').
  struct Crossing {
    uint32_t triangle;
    int sign;         // of the triangle normal's x component
    double xlo, xhi;  // the triangle's x extent: a point beyond it is past the crossing without a predicate
  };
  // The crossings of the line (y, z) = (qy, qz) along x, in any order, into `out` (cleared).
  void rowCrossings(double qy, double qz, std::vector<Crossing>& out) const;
  // inside(p) from rowCrossings(p.y, p.z): a row's cells share the crossings, found once.
  bool inside(const Vec3& p, const std::vector<Crossing>& crossings) const;

 private:
  struct LineNode {
    double lo[2], hi[2];  // (y, z) box
    uint32_t first = 0;   // leaf: first slot in order_; inner: the second child (the first is the next node)
    uint32_t count = 0;   // triangles of a leaf; 0 for an inner node
  };
  void build(const Scene& scene);
  uint32_t buildLineTree(uint32_t begin, uint32_t end);
  // Triangle t of the mesh's, then the caps'.
  const Triangle& triangle(size_t t) const { return t < mesh_.size() ? mesh_[t] : caps_[t - mesh_.size()]; }
  std::shared_ptr<const Scene> framed_;  // the frame constructor's scaled scene, which mesh_ then views
  std::span<const Triangle> mesh_;
  std::vector<Triangle> caps_;
  std::vector<OpenBoundary> boundaries_;
  bool counted_ = false;  // caps built (at most kMaxCapBoundaries holes): k - s; otherwise the tree
  std::vector<LineNode> lineNodes_;
  std::vector<uint32_t> order_;
  WindingTree tree_;     // a soup's
  WindingTree capTree_;  // the caps'
  std::vector<EllipsoidShape> shapes_;
  PowerOfTwoFrame frame_;
};

// Check of a --sdf half-width: finite, > 0, <= kMaxSdfHalfWidth; throws UsageError naming `what` otherwise.
void checkSdfHalfWidth(double halfWidth, const char* what);

// The band: every cell whose centre lies within halfWidth smallest cell edges of a bounded primitive, with its
// signed distance, negative where InsideTest says inside (every cell, occupied or not: grid.solidRuns are not
// used, so a cavity that the flood fill fills keeps the winding number's sign). Work spread over the caller's TBB
// arena; the result does not depend on the thread count. Throws UsageError for a bad half-width, LimitError past the
// memory limit, vox::Error when cancelled.
SdfBand signedDistanceBand(const Grid& grid, const Scene& scene, const SdfOptions& options = {});

// Options whose cells are exactly cubic, for distances: with a resolution and no bounds, the bounds grown about the
// scene's (by less than a cell on each shorter axis) so that every cell has the longest axis' edge, as an OpenVDB
// level set needs (vox-export .vdb). Options with dims or bounds are returned unchanged. Throws as planGrid.
VoxelizeOptions withCubicCells(const Scene& scene, VoxelizeOptions options);

// The numeric domain checks of storeSignedDistances (`signedDistances`), denseSignedDistances (the same) and
// volumeFractions (`fractions`) on the grid `options` plan for `scene`, for tools to refuse before voxelizing.
// Throws InputError with one line (checkNumericDomain), or as planGrid.
void checkNumericDomainOfPlan(const Scene& scene, const VoxelizeOptions& options, bool signedDistances, bool fractions);

// signedDistanceBand stored in `grid` (sdfHalfWidth, sdfKeys, sdfValues), what vox-voxelize --sdf and
// libvox.voxelize(sdf=) do. `filled` is kept for callers: the signs no longer need the fill.
void storeSignedDistances(Grid& grid, const Scene& scene, const SdfOptions& options, bool filled);
// The same, bit for bit, without the copy of the scene in its power-of-two frame (80 bytes a triangle at the peak
// of --sdf's memory): the scene's triangles are scaled into the frame in place and back, exactly as they were, before
// it returns or throws. Copied as above when the way back could round (a coordinate near the smallest normal double
// in a scene scaled down). Nothing else may use `scene` meanwhile. What vox-voxelize --sdf does.
void storeSignedDistancesInPlace(Grid& grid, Scene& scene, const SdfOptions& options);

}  // namespace vox
