// The narrow band's distances, one tile of cells at a time (sdf.cpp bins the primitives into tiles). Two routes give
// the same squared distance at every cell, bit for bit: the value is the minimum over the primitives of
// squaredDistanceToTriangle (closest_point.h) or the ellipsoid's, and a minimum does not depend on the order in
// which it is taken, nor on skipping a primitive that is proven farther.
// - kBoxes: every cell of each primitive's reach box, pruned by squaredDistanceToTriangleWithin against the nearest
//   distance so far (the route of issue 38, kept for the tests).
// - kScan: scan conversion. For each triangle and each row of cells (j, k), the cells whose centres can pass the
//   triangle's lower bound form one interval along x, cut by five half-spaces (the slab about the triangle's plane
//   and the three edges' outward half-spaces, each widened by the bound's reach and rounding allowance). A first
//   pass takes each cell's smallest lower bound and the triangle that gave it; that triangle's exact distance is
//   taken first, so that the second pass prunes every other triangle against a distance that is nearly always the
//   cell's own (docs/distance.md "Cost").
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/distance/closest_point.h"
#include "vox/distance/sdf.h"

namespace vox::band {

// Tiles of kTile^3 cells (sdf.cpp): the tile's cells keep their nearest squared distance in a dense array.
inline constexpr uint32_t kTile = 16;

struct Reachable {
  std::array<std::array<int64_t, 2>, 3> cells;  // inclusive cell ranges of the primitive's box grown by the reach
  bool empty() const { return cells[0][0] > cells[0][1] || cells[1][0] > cells[1][1] || cells[2][0] > cells[2][1]; }
};

// One triangle's row intervals: centres p with cx (p.x - a.x) + cy (p.y - a.y) + cz (p.z - a.z) > c0 for one of
// the constraints (a the first vertex) cannot pass the lower bound within the reach (band_scan.cpp proves it). The
// constraints come sorted: first those that bound x from above (cx >= kMinSlope), then from below, then those too
// nearly parallel to x to bound it, which only empty a row.
struct RowScan {
  struct Constraint {
    double cx, cy, cz, c0, inverse;  // inverse = 1 / cx
  };
  std::array<Constraint, 5> constraints{};
  int upper = 0, lower = 0, count = 0;  // ends of the three groups; count 0: no pruning
  double dxMax = 0;                     // largest |p.x - a.x| over the reach box
};

enum class Route { kBoxes, kScan };

// vox::signedDistanceBand by either route (the library takes kScan; the tests compare the two).
SdfBand signedDistanceBand(const Grid& grid, const Scene& scene, const SdfOptions& options, Route route);

// The primitives as every tile needs them, computed once.
struct Primitives {
  // `reach`: the band's half-width in world units.
  Primitives(const Grid& grid, const Scene& scene, double reach);
  const Grid& grid;
  const Scene& scene;
  std::array<std::vector<double>, 3> centres;  // cell centres by axis
  double reachDistance, reach2;
  std::vector<EllipsoidShape> shapes;
  Box box(size_t p) const;
  // The primitive's box grown by the reach, in cells (computed each time: a table would add 3 MB at 256^3, where the
  // band's peak memory is that of the whole process).
  Reachable reach(size_t p) const;
  // The row constraints of triangle p, whose lower bound is `bound`, in its reach box c (not stored, for the same
  // reason). The bounds are not stored either: at 120 bytes a triangle they were the band's largest table (533 MB
  // at 4.4 M triangles), and a triangle's is recomputed in each of the few tiles its reach meets (about 3): 1.8% of
  // the process's samples at 1.1 M triangles and 1024^3 (docs/distance.md "Not met").
  RowScan rows(size_t p, const TriangleLowerBound& bound, const Reachable& c) const;
  size_t count() const { return scene.triangles.size() + shapes.size(); }
};

// Per-thread scratch of the tile evaluation.
class TileEvaluator {
 public:
  // The nearest squared distance of each of the tile's cells (index i + kTile (j + kTile k) from corner t0) over
  // the primitives prims[0, count), each a primitive whose reach box meets the tile, into `nearest` (kTile^3
  // entries; +infinity where none is within the reach). Entries past the grid are left +infinity.
  void evaluate(const Primitives& primitives, Route route, const int64_t t0[3], const uint32_t* prims, size_t count,
                std::vector<double>& nearest);

 private:
  void boxes(const Primitives& primitives, const int64_t t0[3], const uint32_t* prims, size_t count,
             std::vector<double>& nearest);
  void scan(const Primitives& primitives, const int64_t t0[3], const uint32_t* prims, size_t count,
            std::vector<double>& nearest);
  struct Run {
    uint32_t triangle;
    uint16_t first;  // the first cell's index in the tile
    uint16_t count;
  };
  std::vector<Run> runs_;
  std::vector<double> lowerBounds_;  // the runs' cells' lower bounds, in run order
  std::vector<double> smallest_;     // per cell, the smallest lower bound
  std::vector<uint32_t> nearestTriangle_;
};

}  // namespace vox::band
