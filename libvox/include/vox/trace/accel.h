// The trace-time acceleration structure built from a Grid: primitives prepared for fast tests, the primitives that
// every ray must test (planes, Grid::outsidePrims), and an O(1) lookup of a cell's primitive list by (i,j,k).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/huge_pages.h"
#include "vox/trace/intersect.h"
#include "vox/core/scene.h"

namespace vox {

// `Grid` walks the cells, jumping over the box of empty cells around each empty cell it enters (Accel::cellBoxes,
// issue 27); `Uniform` walks every cell the ray crosses, as the uniform 3D-DDA does (built as a Grid accel without
// cell boxes: buildAccel returns kind Grid); `None` tests every primitive for every ray (brute force, the reference
// for tests).
enum class AccelKind : uint8_t { Grid, None, Uniform };
// Throws UsageError for a name other than "grid", "uniform" or "none".
AccelKind parseAccel(const std::string& name);

// The cell boundaries of a grid as tables: b[a][i] == cellBoundary(bounds, dims, a, i) for i in [0, dims[a]], the
// very same values computed once, so that the walker reads them instead of evaluating the formula (a division by n)
// at every step. Also the per-axis constants the walker's tolerances need. World units.
struct CellBoundaries {
  std::array<uint32_t, 3> dims{0, 0, 0};
  std::array<std::vector<double>, 3> b;
  std::array<double, 3> cellsPerUnit{0, 0, 0};  // n / (b(n) - b(0)): a first guess of a cell index only
  std::array<double, 3> cellSize{0, 0, 0};      // (b(n) - b(0)) / n
  std::array<double, 3> magnitude{0, 0, 0};     // max(|b(0)|, |b(n)|)
  double minCell = 0;                           // smallest positive cellSize, 0 when there is none
};
CellBoundaries makeCellBoundaries(const Box& bounds, const std::array<uint32_t, 3>& dims);

// Single-precision copies of the occupied cells' triangles for the float filter of the single-ray walk
// (trace/float_filter.h, issue 12): four triangles to a group in structure-of-arrays form, each cell's groups next to
// each other in cell order. Coordinates are scaled: x' = (x - center) * scale (scale a power of two, so the double
// values scale exactly), then rounded to float. The filter only rejects triangles that a proven bound says the double
// test would miss; the rest go to that test, so hits stay bit for bit.
struct TriangleGroup4 {
  float lane[12][4];  // rows: v0 x y z, e1 x y z, e2 x y z, n x y z (n = e1 x e2 of the double data, scaled by scale^2)
  uint32_t id[4];     // triangle ids (lanes past the cell's count are unused)
};
struct FloatCells {
  bool enabled = false;  // false when the scene's scale or values are outside what the bound covers
  Vec3 center;
  double scale = 1;
  // Upper bounds over every group, scaled units: |v0' - 0| (vertexMax), |e1'|, |e2'| (edgeMax), |n'| (normalMax).
  std::array<double, 3> vertexMax{0, 0, 0}, edgeMax{0, 0, 0}, normalMax{0, 0, 0};
  // Per occupied cell c: groups [first[c], first[c] + (count[c] + 3) / 4), count[c] triangles (the cell's leading
  // triangle ids; spheres follow them in grid->primIds).
  struct Cell {
    uint32_t first, count;
  };
  HugeVector<Cell> cells;
  HugeVector<TriangleGroup4> groups;
  // cells[] entries laid out as Accel::cellSlots ({0, 0} for empty and solid cells), so that a walk reads a cell's
  // groups with one dependent read less (Accel::floatCell). Empty when the accel has no block tables.
  HugeVector<Cell> slots;
};

inline constexpr uint32_t kEmptyCell = 0xffffffffu;
// Accel::cellBoxes: cells the box reaches below (lo) and above (hi) its cell on each axis, at most kMaxBoxReach.
struct CellBox {
  uint8_t lo[3], hi[3];
};
inline constexpr uint32_t kMaxBoxReach = 255;
inline constexpr uint32_t kSolidCell = 0xfffffffeu;

struct Accel {
  AccelKind kind = AccelKind::Grid;
  const Grid* grid = nullptr;  // not owned: the Grid must outlive the Accel
  uint32_t triangleCount = 0, sphereCount = 0, planeCount = 0;
  HugeVector<TriangleData> triangles;
  std::vector<SphereData> spheres;
  std::vector<Plane> planes;
  // Planes and Grid::outsidePrims, ascending ids: tested for every ray, before the walk.
  std::vector<uint32_t> alwaysTested;
  // Boundary tables of the grid, for the walker.
  CellBoundaries boundaries;

  // Two-level lookup: the grid is cut into blocks of 2^blockShift cells a side; blockSlot holds, for each block,
  // kEmptyCell or the index of its table in cellSlots (2^(3*blockShift) entries, x fastest), whose entries are the
  // occupied-cell index into grid->cellStart, kSolidCell or kEmptyCell. blockShift == 0 means the grid was too big
  // or too scattered for tables, and lookups fall back to a binary search in grid->cellKeys.
  uint32_t blockShift = 0;
  std::array<uint32_t, 3> blockDims{0, 0, 0};
  HugeVector<uint32_t> blockSlot;
  HugeVector<uint32_t> cellSlots;
  // Per block (blockSlot order): 0 when the block holds a cell, else the largest s >= blockShift such that the
  // aligned box of 2^s cells a side holding the block is empty (cells past the grid count as empty; s stops at the
  // box holding the whole grid), so that a walk skips a run of empty space in one jump per box rather than per block
  // (GridWalker::fastForward; issue 12). Empty when there are no block tables.
  HugeVector<uint8_t> emptyShift;
  // The triangles of the cells, copied in cell order: cellTriangles[r] == triangles[grid->primIds[r]] when that id is
  // a triangle (unused otherwise). A walk then reads a cell's triangles from one run of memory instead of one random
  // place each (a dependent cache miss per test for incoherent rays, issue 12); the same values, so the same t.
  // Empty when it would take more than kMaxCellTriangleBytes; walks then read `triangles` by id.
  HugeVector<TriangleData> cellTriangles;
  // The float copies of the cells' triangles for the single-ray walk (AccelKind::Grid; empty over the budget).
  FloatCells floatCells;
  // Per cell slot (laid out as cellSlots), for an empty or solid cell: the box of cells around it that holds no
  // primitive, as the number of cells it reaches below and above the cell on each axis (0 for an occupied cell).
  // A walk that enters such a cell has nothing to test until it leaves the box, and jumps to its exit (issue 27;
  // trace/cell_boxes.cpp). Empty for AccelKind::Uniform, without block tables, or for grids over kMaxBoxGridCells.
  HugeVector<CellBox> cellBoxes;

  uint32_t primitiveCount() const { return triangleCount + sphereCount + planeCount; }

  // kEmptyCell, kSolidCell or the occupied-cell index of cell (i,j,k); indices must be inside the grid.
  uint32_t lookup(uint32_t i, uint32_t j, uint32_t k) const {
    if (blockShift != 0) {
      const uint32_t s = blockShift;
      const uint32_t b = blockSlot[(i >> s) + blockDims[0] * ((j >> s) + uint64_t(blockDims[1]) * (k >> s))];
      if (b == kEmptyCell) return kEmptyCell;
      const uint32_t m = (1u << s) - 1;
      return cellSlots[(uint64_t(b) << (3 * s)) + ((i & m) | ((j & m) << s) | ((k & m) << (2 * s)))];
    }
    return lookupSlow(i, j, k);
  }
  uint32_t lookupSlow(uint32_t i, uint32_t j, uint32_t k) const;
  // The float groups of cell (i,j,k) ({0, 0} when it holds no triangle), through the block tables; only when
  // floatCells.slots is not empty.
  FloatCells::Cell floatCell(uint32_t i, uint32_t j, uint32_t k) const {
    const uint32_t s = blockShift;
    const uint32_t b = blockSlot[(i >> s) + blockDims[0] * ((j >> s) + uint64_t(blockDims[1]) * (k >> s))];
    if (b == kEmptyCell) return {0, 0};
    const uint32_t m = (1u << s) - 1;
    return floatCells.slots[(uint64_t(b) << (3 * s)) + ((i & m) | ((j & m) << s) | ((k & m) << (2 * s)))];
  }
  // The slot of cell (i,j,k) in cellSlots (and cellBoxes, floatCells.slots), or UINT64_MAX in an empty block; only
  // with block tables.
  uint64_t slotOf(uint32_t i, uint32_t j, uint32_t k) const {
    const uint32_t s = blockShift;
    const uint32_t b = blockSlot[(i >> s) + blockDims[0] * ((j >> s) + uint64_t(blockDims[1]) * (k >> s))];
    if (b == kEmptyCell) return UINT64_MAX;
    const uint32_t m = (1u << s) - 1;
    return (uint64_t(b) << (3 * s)) + ((i & m) | ((j & m) << s) | ((k & m) << (2 * s)));
  }
  // True when the whole block holding cell (i,j,k) is empty (always false without tables).
  bool blockEmpty(uint32_t i, uint32_t j, uint32_t k) const {
    if (blockShift == 0) return false;
    const uint32_t s = blockShift;
    return blockSlot[(i >> s) + blockDims[0] * ((j >> s) + uint64_t(blockDims[1]) * (k >> s))] == kEmptyCell;
  }
  std::span<const uint32_t> cellPrims(uint32_t occupiedIndex) const { return grid->cellPrims(occupiedIndex); }
};

// Fills accel.emptyShift from accel.blockSlot (nothing without block tables).
void buildEmptyShift(Accel& accel);
// Fills accel.cellBoxes from the block tables (nothing without them, or for grids over kMaxBoxGridCells cells): for
// each empty or solid cell, a box of cells holding no primitive, grown greedily one layer at a time, each of the six
// faces in turn, while the layer holds no occupied cell and the reach stays within kMaxBoxReach.
inline constexpr uint64_t kMaxBoxGridCells = uint64_t(1) << 25;
void buildCellBoxes(Accel& accel);

inline constexpr uint64_t kMaxCellTriangleBytes = uint64_t(128) << 20;

// The ray test of primitive `id` (any kind), as every traversal calls it.
inline bool intersectPrimitive(const Accel& accel, uint32_t id, const Ray& ray, double& t) {
  if (id < accel.triangleCount) return intersectTriangle(accel.triangles[id], ray, t);
  const uint32_t s = id - accel.triangleCount;
  if (s < accel.sphereCount) return intersectSphere(accel.spheres[s], ray, t);
  return intersectPlane(accel.planes[s - accel.sphereCount], ray, t);
}

// Triangle `id` at position `ref` of grid->primIds (id == grid->primIds[ref] < triangleCount): its copy in
// Accel::cellTriangles when there is one, read from the run of memory after the cell's ids instead of a random
// place; the same TriangleData either way.
inline const TriangleData& cellTriangle(const Accel& accel, uint64_t ref, uint32_t id) {
  return accel.cellTriangles.empty() ? accel.triangles[id] : accel.cellTriangles[ref];
}

// The test of intersectPrimitive for the primitive at position `ref` of grid->primIds (id == grid->primIds[ref]),
// reading a triangle through cellTriangle: the same TriangleData, so the same result and t.
inline bool intersectCellPrimitive(const Accel& accel, uint64_t ref, uint32_t id, const Ray& ray, double& t) {
  if (id < accel.triangleCount) return intersectTriangle(cellTriangle(accel, ref, id), ray, t);
  return intersectPrimitive(accel, id, ray, t);
}

// Prepares every primitive of `scene` and the cell lookup of `grid` (which must have been built from `scene`; the
// Accel keeps a pointer to it). Throws InputError when the grid names primitive ids that
// the scene does not have, vox::Error for a singular ellipsoid transform, LimitError when the grid has 2^32 - 2 or
// more occupied cells.
Accel buildAccel(const Scene& scene, const Grid& grid, AccelKind kind);

}  // namespace vox
