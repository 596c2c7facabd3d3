// Voxelization: put each bounded primitive of a scene into the cells it meets (DESIGN.md "Grid").
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "vox/core/brick_layout.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"

namespace vox {

struct VoxelizeOptions {
  std::optional<Box> bounds;                    // user bounds; default: scene bounds, zero-width axes padded
  std::optional<std::array<uint32_t, 3>> dims;  // --grid
  std::optional<uint32_t> resolution;           // --res: cells on the longest axis
  OverlapMethod method = OverlapMethod::Exact;
  uint64_t memoryLimitBytes = 16ull << 30;  // refuse requests whose estimate exceeds this, before allocating
  // Called with a fraction in [0, 1] from worker threads; return false to cancel (throws vox::Error).
  std::function<bool(double)> progress;
};

struct VoxelizeStats {
  uint64_t cellsTested = 0;     // primitive-cell overlap tests evaluated
  uint64_t exactFallbacks = 0;  // tests that the floating-point filter could not decide (exact method)
  uint64_t degenerateTriangles = 0;
  double seconds = 0;  // time in voxelization alone
};

// Chosen from the resolution sweep of bench/tradeoff.sh (docs/tradeoff.md): the fastest exact grids for tracing the
// meshes had 1.3 to 5 cells per primitive (median 3); at 3 the default traced within 6% of the best swept
// resolution on 8 of 9 scenes (1.7x on SheenCloth).
inline constexpr double kCellsPerPrimitive = 3;

// Grid bounds and dimensions for `scene` under `options`, without voxelizing. Empty cell lists. Throws UsageError
// for invalid bounds or dimensions (0, or more than kMaxCellsPerAxis per axis). A scene without bounded primitives
// and without user bounds gets a 1x1x1 grid over the unit cube.
Grid planGrid(const Scene& scene, const VoxelizeOptions& options);

// Dimensions chosen by the default heuristic: about kCellsPerPrimitive cells per bounded primitive, cubic cells.
std::array<uint32_t, 3> defaultDims(const Box& bounds, size_t boundedPrimitives);
std::array<uint32_t, 3> dimsForResolution(const Box& bounds, uint32_t resolution);

// The bounded primitives whose bounding boxes stick out of grid.bounds, ascending (what voxelizeScene puts in
// grid.outsidePrims when the bounds are the user's).
std::vector<uint32_t> primitivesOutside(const Scene& scene, const Grid& grid);

// One brick of a grid set: the cells of `window` of the grid `plan` (planGrid's result: its bounds, dims, method and
// outsidePrims are kept, its cells ignored), holding exactly what voxelizeScene's grid holds in those cells, provided
// `ids` (ascending bounded primitive ids) contains every primitive whose bounding box meets the window. Cell keys are
// keys of the whole grid. Throws UsageError for a window outside the grid or an id that is not a bounded primitive,
// LimitError as voxelizeScene (the estimate covers the window only).
Grid voxelizeBrick(const Scene& scene, const Grid& plan, const CellWindow& window, std::span<const uint32_t> ids,
                   const VoxelizeOptions& options, VoxelizeStats* stats = nullptr);

// Voxelizes every bounded primitive of `scene`. Work is spread over the TBB arena of the caller.
// Throws UsageError (bad options), LimitError (estimated memory over options.memoryLimitBytes, checked before the
// big allocations). Precondition: validateScene(scene) passed.
Grid voxelizeScene(const Scene& scene, const VoxelizeOptions& options, VoxelizeStats* stats = nullptr);

}  // namespace vox
