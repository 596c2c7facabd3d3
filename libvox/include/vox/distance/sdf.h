// Signed distance fields (DESIGN.md "Distance and volume"): the narrow band of `--sdf`, and the inside test that signs
// it. Distances are Euclidean, in world units, to the nearest point of any bounded primitive (triangles, spheres,
// ellipsoids; planes are left out); negative inside the solid as `--fill` decides it. The sign never scales the
// magnitude. Error bound against the exact distance: docs/distance.md.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/math.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/core/scene.h"
#include "vox/distance/closest_point.h"
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
// winding number has magnitude >= kWindingThreshold: the test `--fill` applies to its runs (fill.h), so a closed
// surface decides exactly, an open or self-intersecting one as the fill does.
class InsideTest {
 public:
  explicit InsideTest(const Scene& scene);
  // The same over the scene scaled into `frame` (vox/core/power_of_two_frame.h): `inside` then takes points in
  // that frame, where winding numbers of a scene at 1e-300 or 1e300 neither underflow nor overflow.
  InsideTest(const Scene& scene, const PowerOfTwoFrame& frame);
  bool inside(const Vec3& p) const;
  const PowerOfTwoFrame& frame() const { return frame_; }

 private:
  WindingTree tree_;
  std::vector<EllipsoidShape> shapes_;
  PowerOfTwoFrame frame_;
};

// Check of a --sdf half-width: finite, > 0, <= kMaxSdfHalfWidth; throws UsageError naming `what` otherwise.
void checkSdfHalfWidth(double halfWidth, const char* what);

// The band: every cell whose centre lies within halfWidth smallest cell edges of a bounded primitive, with its
// signed distance. The sign of an empty cell is its fill status (precondition: grid.solidRuns as fillSolid set
// them for this scene); an occupied cell's centre gets InsideTest. Work spread over the caller's TBB arena; the
// result does not depend on the thread count. Throws UsageError for a bad half-width, LimitError past the memory
// limit, vox::Error when cancelled.
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
// libvox.voxelize(sdf=) do. `filled`: grid.solidRuns are fillSolid's for this scene; otherwise the fill runs on the
// side first (its runs are not kept, and its progress is the first third of options.progress).
void storeSignedDistances(Grid& grid, const Scene& scene, const SdfOptions& options, bool filled);

}  // namespace vox
