// The sparse uniform grid (DESIGN.md "Grid"). Cell (i,j,k) is the closed box between cellBoundary(a, i) and
// cellBoundary(a, i+1) on each axis a; that one formula is used by voxelization, traversal and export alike.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vox/core/huge_pages.h"
#include "vox/core/math.h"

namespace vox {

// A run of consecutive cell keys first .. first + count - 1 (count >= 1). Solid interiors are long runs along x,
// so a filled 2048^3 grid costs megabytes, not the 8 GiB of one key per cell.
struct CellRun {
  uint64_t first = 0;
  uint64_t count = 0;
};

inline constexpr uint32_t kMaxCellsPerAxis = 1u << 21;  // keeps every cell key below 2^63

enum class OverlapMethod : uint8_t { Center = 0, BBox = 1, Sat = 2, Exact = 3 };

std::string methodName(OverlapMethod method);
// Throws InputError for an unknown name.
OverlapMethod parseMethod(const std::string& name);

// Cells are stored sparsely in compressed-row form: cellKeys (sorted linear cell indices, key = i + nx*(j + ny*k))
// and, for occupied cell c, the primitive ids primIds[cellStart[c] .. cellStart[c+1]), ascending.
struct Grid {
  Box bounds;
  std::array<uint32_t, 3> dims{1, 1, 1};
  OverlapMethod method = OverlapMethod::Exact;
  HugeVector<uint64_t> cellKeys;  // large ones on whole huge pages (vox/core/huge_pages.h)
  HugeVector<uint64_t> cellStart{0};
  HugeVector<uint32_t> primIds;
  // Bounded primitives that stick out of user-given bounds: tracing tests them for every ray, like planes.
  std::vector<uint32_t> outsidePrims;
  // Cells inside the surface (--fill): sorted, disjoint, non-adjacent runs of keys. They hold no primitive; a cell
  // may be both occupied and solid (tracing and export treat it as occupied).
  std::vector<CellRun> solidRuns;
  // Signed distances (--sdf, DESIGN.md "Distance and volume"): the sorted keys of the cells whose centre lies within
  // sdfHalfWidth smallest cell edges of the surface, and the signed distance at each centre (negative inside).
  // Empty, with sdfHalfWidth 0, when not computed.
  double sdfHalfWidth = 0;
  std::vector<uint64_t> sdfKeys;
  std::vector<double> sdfValues;
  // Volume fractions (--fraction): for each occupied cell (the order of cellKeys), the fraction of its closed box
  // inside the solid, in [0, 1]. Empty when not computed; solid cells count 1 without an entry.
  std::vector<double> fractions;

  uint64_t cellCount() const { return uint64_t(dims[0]) * dims[1] * dims[2]; }
  size_t occupiedCount() const { return cellKeys.size(); }
  size_t referenceCount() const { return primIds.size(); }
  uint64_t solidCount() const {
    uint64_t n = 0;
    for (const CellRun& r : solidRuns) n += r.count;
    return n;
  }
  std::span<const uint32_t> cellPrims(size_t occupiedIndex) const {
    return {primIds.data() + cellStart[occupiedIndex], primIds.data() + cellStart[occupiedIndex + 1]};
  }
};

inline uint64_t cellKey(const std::array<uint32_t, 3>& dims, uint64_t i, uint64_t j, uint64_t k) {
  return i + dims[0] * (j + uint64_t(dims[1]) * k);
}
inline std::array<uint32_t, 3> cellIndex(const std::array<uint32_t, 3>& dims, uint64_t key) {
  return {uint32_t(key % dims[0]), uint32_t((key / dims[0]) % dims[1]), uint32_t(key / (uint64_t(dims[0]) * dims[1]))};
}

// b_a(i) = lo_a + (hi_a - lo_a) * i / n_a, in double precision, evaluated exactly in this order. i in [0, n_a].
// Every grid libvox makes or reads satisfies b_a(0) == lo_a and b_a(n_a) == hi_a exactly (planGrid nudges hi by a few
// ulps where needed; readGridFile refuses a file that breaks it), so the cells tile the bounds without a sliver.
inline double cellBoundary(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, int64_t i) {
  return bounds.lo[axis] + (bounds.hi[axis] - bounds.lo[axis]) * double(i) / double(dims[axis]);
}
Box cellBox(const Grid& grid, uint32_t i, uint32_t j, uint32_t k);
// The centre of cell i on `axis`: the midpoint of its two boundaries, as every centre in libvox is computed.
inline double cellCentreOnAxis(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, int64_t i) {
  return 0.5 * (cellBoundary(bounds, dims, axis, i) + cellBoundary(bounds, dims, axis, i + 1));
}
// The centre of the cell with `key`.
Vec3 cellCentre(const Grid& grid, uint64_t key);
// cellCentreOnAxis for every index of every axis: [axis][i], computed once for loops over many cells.
std::array<std::vector<double>, 3> cellCentresByAxis(const Grid& grid);

// Index of the occupied cell with `key`, or -1. O(log occupied).
int64_t findCell(const Grid& grid, uint64_t key);
// Whether `key` lies in one of grid.solidRuns. O(log runs).
bool isSolid(const Grid& grid, uint64_t key);
// Appends `key` to sorted runs, extending the last run when adjacent. Keys must come in increasing order.
void appendSolidKey(std::vector<CellRun>& runs, uint64_t key);
// Throws InputError (prefixed by `what`) unless the runs are sorted, disjoint, non-adjacent, non-empty and inside
// a grid of `cellCount` cells.
void checkSolidRuns(const std::vector<CellRun>& runs, uint64_t cellCount, const std::string& what);
// Throws InputError (prefixed by `what`) when a solid run covers an occupied cell: a cell is occupied or solid,
// never both (counting it twice would make vox-info and the exports disagree). `sortedKeys` ascending, `runs` as
// checkSolidRuns accepts them. O(cells + runs).
void checkSolidRunsMissCells(std::span<const uint64_t> sortedKeys, const std::vector<CellRun>& runs,
                             const std::string& what);

// Throws vox::Error naming `what` ("... not written") unless the grid holds what every reader accepts: occupied
// keys strictly ascending inside the grid with their cell starts, solid runs as checkSolidRuns wants them, a band
// of strictly ascending keys inside the grid with one finite value each and a half-width in (0, 64], and one
// fraction in [0, 1] per occupied cell. Writers call it before opening their output, so that no file is ever
// written that a reader would refuse, and no dense array is indexed by a key past its end. O(cells stored).
void checkGridBeforeWrite(const Grid& grid, const std::string& what);

// Smallest index range [first, last] of cells on `axis` whose closed boxes meet [lo, hi] (clamped to the grid);
// uses cellBoundary, so a coordinate exactly on a boundary yields both neighbouring cells. first > last when the
// interval misses the grid.
std::array<int64_t, 2> cellRange(const Box& bounds, const std::array<uint32_t, 3>& dims, int axis, double lo,
                                 double hi);

}  // namespace vox
